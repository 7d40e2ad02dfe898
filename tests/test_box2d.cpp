// The Box2D 2.4.1 adapter: against the exact model, inside the room, at the
// seed's dt, and one test per trap (Box2D's default restored through
// box2d::Tuning, its physical consequence measured).
#include "engines/box2d/box2d_adapter.h"
#include "engines/engine.h"
#include "exact/exact_model.h"
#include "metrics/summary.h"
#include "scenarios/loader.h"
#include "tests/support/cli.h"
#include "tests/support/engine_run.h"
#include "tests/support/engine_tests.h"
#include "tests/support/scenarios.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace bouncecheck {
namespace {

namespace fs = std::filesystem;
using test::FloorHit;
using test::floor_hits;
using test::setting;
using Box2dRun = test::SimulatorRun;

Scenario seed(const char* name) { return test::bundled_seed(name); }

Box2dRun run_box2d(const Scenario& s, const box2d::Tuning& tuning = {}) {
    return test::record_states(*box2d::make_simulator(tuning), s);
}

Scenario with_per_contact(Scenario s) {
    EngineOptions o;
    o.tangential_model = TangentialModel::per_contact;
    s.engines["box2d"] = o;
    return s;
}

// A drop with a floor contact first: centre at 0.5, moving sideways at 0.1.
Scenario friction_drop(double mu, bool free_rotation = true) {
    Scenario s = seed("seed-2d.toml");
    s.position = {0.5, 0.5, 0};
    s.velocity = {0.1, 0, 0};
    s.dt = 1e-3;
    s.duration = 3.2;  // first floor contact at 3.03 s
    EngineOptions o;
    o.friction = mu;
    o.free_rotation = free_rotation;
    s.engines["box2d"] = o;
    return s;
}

// A low drop: 1 cm above the floor, floor impact at 0.0443 m/s.
Scenario low_drop() {
    Scenario s = seed("seed-2d.toml");
    s.position = {0.5, 0.06, 0};
    s.velocity = {0, 0, 0};
    s.dt = 1e-3;
    s.duration = 1.0;
    return s;
}

// ---------------------------------------------------------------- capabilities

TEST(Box2dCapabilities, TwoDimensionalFloatEngine) {
    const auto sim = box2d::make_simulator({});
    const auto* engine = dynamic_cast<const EngineSimulator*>(sim.get());
    ASSERT_NE(engine, nullptr);
    EXPECT_EQ(sim->name(), "box2d");
    const EngineCapabilities caps = engine->capabilities();
    EXPECT_FALSE(caps.runs_3d);
    EXPECT_TRUE(caps.runs_2d);
    EXPECT_TRUE(caps.per_contact_hook);
    EXPECT_EQ(caps.precision, "float");

    Scenario s = seed("seed-2d.toml");
    s.duration = 0.3;
    const Box2dRun r = run_box2d(s);
    EXPECT_EQ(setting(r.summary, "engine").substr(0, 11), "Box2D 2.4.1");
    EXPECT_EQ(setting(r.summary, "precision"), "float");
    // The state read back is float: x = 0.5 + 0.3 t in engine metres (x 20) is a float.
    const double x_engine = r.states.back().p.x() * 20.0;
    EXPECT_NEAR(x_engine, static_cast<double>(static_cast<float>(x_engine)), 1e-12);
}

TEST(Box2dCapabilities, Seed3dIsSkippedThroughTheRegistry) {
    const auto sim = test::find_simulator("box2d");
    const auto why = sim->cannot_run(seed("seed-3d.toml"));
    ASSERT_TRUE(why.has_value());
    EXPECT_NE(why->find("2D"), std::string::npos) << *why;
    EXPECT_FALSE(sim->cannot_run(seed("seed-2d.toml")).has_value());
    EXPECT_FALSE(sim->cannot_run(with_per_contact(seed("seed-2d.toml"))).has_value());
}

TEST(Box2dCapabilities, CliRunsSeed3dWithBox2dSkipped) {
    const fs::path out = fs::temp_directory_path() / ("bouncecheck-box2d-cli-" + std::to_string(::getpid()));
    fs::remove_all(out);
    const test::CliResult r = test::bouncecheck(std::string("run ") + BOUNCECHECK_SCENARIO_DIR +
                                                "/seed-3d.toml --engines reference,exact,box2d --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("box2d"), std::string::npos) << r.output;
    const auto report = nlohmann::json::parse(test::slurp(out / "report.json"));
    ASSERT_EQ(report["scenarios"].size(), 1u);
    const auto& sims = report["scenarios"][0]["simulators"];
    ASSERT_EQ(sims.size(), 3u);
    EXPECT_EQ(sims[0]["status"], "ok");
    EXPECT_EQ(sims[1]["status"], "ok");
    EXPECT_EQ(sims[2]["simulator"], "box2d");
    EXPECT_EQ(sims[2]["status"], "skipped");
    EXPECT_NE(sims[2]["reason"].get<std::string>().find("2D"), std::string::npos) << sims[2].dump();
    fs::remove_all(out);
}

// ---------------------------------------------------------------- against exact

// seed-2d with per-contact damping (the law's beta inside the engine) at dt = 1e-3.
TEST(Box2dVsExact, FirstFloorContactApexesAndRestitution) {
    Scenario s = with_per_contact(seed("seed-2d.toml"));
    s.dt = 1e-3;
    s.duration = 19.5;  // past the fourth apex (the initial one and three bounces)
    const ExactModel exact(s);
    const Box2dRun r = run_box2d(s);
    ASSERT_EQ(r.summary.status, RunStatus::ok) << r.summary.reason;

    const auto hits = floor_hits(r.states, s.radius);
    ASSERT_GE(hits.size(), 3u);
    double t_exact = -1;
    for (const WallContact& c : exact.contacts())
        if (c.axis == 1 && c.side < 0) {
            t_exact = c.t;
            break;
        }
    ASSERT_GT(t_exact, 0);
    // The first sample after the contact lies within one step of it; Box2D's
    // bounce lands in the step that overlaps (no TOI at this dt: the step's
    // travel, 8 mm engine, is below the 15 mm TOI target), one more step at most.
    EXPECT_NEAR(hits[0].after.t, t_exact, 2 * s.dt);

    // Apexes: the initial one and three after bounces. Each bounce may land up
    // to one step late with the ball up to one step of travel (0.42 mm) inside
    // the floor; the position solver then lifts it without velocity, so each
    // apex can be off by about one step of travel plus the slop (0.25 mm). The
    // errors compound over three bounces: 1 mm.
    ASSERT_GE(r.summary.apexes.size(), 4u);
    ASSERT_GE(exact.apexes().size(), 4u);
    for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(r.summary.apexes[i].height, exact.apexes()[i].height, 1e-3) << "apex " << i;

    // Restitution measured from the stream: the samples straddle the contact,
    // so gravity acts for up to one step on each side (g dt on each speed,
    // 2.3e-4 relative at 0.42 m/s), plus float round-off.
    const double g_dt = std::abs(s.gravity.y()) * s.dt;
    const double tol = (1 + s.alpha) * g_dt / std::abs(hits[0].before.v.y()) + 1e-4;
    EXPECT_NEAR(hits[0].restitution(), s.alpha, tol);
    // And the tangential velocity was scaled by beta once (per-contact hook).
    EXPECT_NEAR(hits[0].after.v.x(), s.beta * hits[0].before.v.x(), 1e-6);
}

TEST(Box2dVsExact, BallNeverLeavesTheRoom) {
    for (const double dt : {0.03, 1e-3}) {
        Scenario s = seed("seed-2d.toml");
        s.dt = dt;
        s.duration = dt > 0.01 ? 50.0 : 12.0;
        const Box2dRun r = run_box2d(s);
        ASSERT_EQ(r.summary.status, RunStatus::ok) << r.summary.reason;
        // Box2D leaves up to b2_linearSlop of penetration (0.25 mm at scale
        // 20) and a continuous-collision stop lies up to 3 slop inside the
        // skin (0.75 mm): 1 mm.
        const double tol = 1e-3;
        for (const State& st : r.states)
            for (int i = 0; i < 2; ++i) {
                ASSERT_GE(st.p[i], s.radius - tol) << "dt " << dt << " t " << st.t << " axis " << i;
                ASSERT_LE(st.p[i], s.room[i] - s.radius + tol) << "dt " << dt << " t " << st.t << " axis " << i;
            }
    }
}

TEST(Box2dSeed, Seed2dAtSeedDtBounces) {
    const Scenario s = seed("seed-2d.toml");
    const auto run = test::run_simulator("box2d", s);
    ASSERT_EQ(run.summary.status, RunStatus::ok) << run.summary.reason;
    EXPECT_EQ(run.summary.steps, 1667);
    EXPECT_GE(run.summary.floor_contacts, 5);
    ASSERT_GE(run.summary.apexes.size(), 5u);
    // The bouncing part: later apexes are the micro-hops of a resting ball.
    for (std::size_t i = 1; i < 5; ++i) EXPECT_LT(run.summary.apexes[i].height, run.summary.apexes[i - 1].height);
    // The same through per-contact damping.
    const auto pc = test::run_simulator("box2d", with_per_contact(s));
    ASSERT_EQ(pc.summary.status, RunStatus::ok) << pc.summary.reason;
    EXPECT_GE(pc.summary.floor_contacts, 5);
}

// ---------------------------------------------------------------- traps

// b2FixtureDef::restitutionThreshold defaults to 1 m/s: slower impacts stick.
TEST(Box2dTrap, RestitutionThreshold) {
    Scenario s = seed("seed-2d.toml");
    s.dt = 1e-3;
    s.duration = 4.5;  // first floor impact at 4.28 s, 0.42 m/s
    const Box2dRun ours = run_box2d(s);
    EXPECT_EQ(setting(ours.summary, "restitution_threshold"), "0 m/s (engine)");
    auto hits = floor_hits(ours.states, s.radius);
    ASSERT_FALSE(hits.empty());
    EXPECT_NEAR(hits[0].restitution(), 0.8, 1e-3);

    // Box2D's default without scaling: the seed's floor impact does not bounce at all.
    box2d::Tuning dflt;
    dflt.restitution_threshold = 1.0f;
    dflt.length_scale = 1.0;
    hits = floor_hits(run_box2d(s, dflt).states, s.radius);
    ASSERT_FALSE(hits.empty());
    EXPECT_LT(hits[0].restitution(), 0.01);

    // Even scaled (1 m/s engine = 0.05 m/s), a 1 cm drop stops dead.
    dflt.length_scale = 0.0;
    const Scenario low = low_drop();
    hits = floor_hits(run_box2d(low, dflt).states, low.radius);
    ASSERT_FALSE(hits.empty());
    EXPECT_LT(hits[0].restitution(), 0.01);
    hits = floor_hits(run_box2d(low).states, low.radius);
    ASSERT_FALSE(hits.empty());
    EXPECT_NEAR(hits[0].restitution(), 0.8, 0.01);
}

// b2MixFriction = sqrt(f1 f2): the walls' default 0.2 changes the ball's mu.
TEST(Box2dTrap, FrictionCombine) {
    const double mu = 0.05;
    const Scenario s = friction_drop(mu);
    auto effective_mu = [&](const box2d::Tuning& t) {
        const auto hits = floor_hits(run_box2d(s, t).states, s.radius);
        EXPECT_EQ(hits.size(), 1u);
        if (hits.empty()) return -1.0;
        // Sliding throughout: the friction impulse is mu x the normal impulse.
        const FloorHit& h = hits[0];
        return (h.before.v.x() - h.after.v.x()) / (h.after.v.y() - h.before.v.y());
    };
    const Box2dRun ours = run_box2d(s);
    EXPECT_EQ(setting(ours.summary, "friction"), "ball 0.05 walls 0.05");
    // The normal impulse also carries one step of gravity (g dt / 0.53 m/s = 2e-4 relative).
    EXPECT_NEAR(effective_mu({}), mu, 1e-3);
    box2d::Tuning no_override;
    no_override.override_mix = false;
    EXPECT_NEAR(effective_mu(no_override), mu, 1e-3);  // both fixtures mu: sqrt(mu mu) = mu
    box2d::Tuning dflt = no_override;
    dflt.wall_friction = 0.2f;  // Box2D's default on the walls
    EXPECT_GT(effective_mu(dflt), 1.2 * mu);
}

// b2MixRestitution = max(r1, r2): whichever fixture is larger wins.
TEST(Box2dTrap, RestitutionCombine) {
    const Scenario s = friction_drop(0.0);
    auto restitution = [&](const box2d::Tuning& t) {
        const auto hits = floor_hits(run_box2d(s, t).states, s.radius);
        EXPECT_EQ(hits.size(), 1u);
        return hits.empty() ? -1.0 : hits[0].restitution();
    };
    box2d::Tuning elastic_walls;
    elastic_walls.wall_restitution = 1.0f;
    elastic_walls.override_mix = false;
    EXPECT_NEAR(restitution(elastic_walls), 1.0, 2e-3);  // max(0.8, 1)
    elastic_walls.override_mix = true;                   // PreSolve sets alpha per contact
    EXPECT_NEAR(restitution(elastic_walls), 0.8, 2e-3);
    box2d::Tuning default_walls;
    default_walls.wall_restitution = 0.0f;  // Box2D's default: max(0.8, 0) = 0.8
    default_walls.override_mix = false;
    EXPECT_NEAR(restitution(default_walls), 0.8, 2e-3);
    const Box2dRun ours = run_box2d(s);
    EXPECT_EQ(setting(ours.summary, "restitution"), "ball 0.8 walls 0.8");
    EXPECT_NE(setting(ours.summary, "combine_override").find("PreSolve"), std::string::npos);
}

// b2_polygonRadius: polygons collide with a 1 cm (engine) skin.
TEST(Box2dTrap, PolygonSkin) {
    Scenario s = seed("seed-2d.toml");
    s.dt = 1e-3;
    s.duration = 4.5;
    auto first_bounce_low = [&](const box2d::Tuning& t) {
        const Box2dRun r = run_box2d(s, t);
        double low = 1e9;
        for (const State& st : r.states)
            if (st.t > 4.0) low = std::min(low, st.p.y());
        return low;
    };
    box2d::Tuning unscaled;
    unscaled.length_scale = 1.0;
    box2d::Tuning unscaled_skin = unscaled;
    unscaled_skin.compensate_skin = false;
    // Unscaled, the skin stops the ball 1 cm (a fifth of its radius) above the floor.
    EXPECT_GT(first_bounce_low(unscaled_skin), s.radius + 0.009);
    EXPECT_LT(first_bounce_low(unscaled), s.radius + 0.0005);
    // Scaled (the default), it is still 0.5 mm: the ball turns above the floor.
    box2d::Tuning skin;
    skin.compensate_skin = false;
    EXPECT_GT(first_bounce_low(skin), s.radius);
    EXPECT_LT(first_bounce_low({}), s.radius);
    EXPECT_NE(setting(run_box2d(s).summary, "wall_skin").find("outside the room"), std::string::npos);
}

// b2_linearSlop (5 mm) and the TOI target (3 slop) are a tenth and a third of
// the unscaled 5 cm ball.
TEST(Box2dTrap, LinearSlopNeedsScaling) {
    Scenario s = with_per_contact(seed("seed-2d.toml"));  // dt = 0.03; per-contact for exact's timing
    s.duration = 5.0;
    const ExactModel exact(s);
    box2d::Tuning unscaled;
    unscaled.length_scale = 1.0;
    const auto bad = floor_hits(run_box2d(s, unscaled).states, s.radius);
    const Box2dRun ours = run_box2d(s);
    const auto good = floor_hits(ours.states, s.radius);
    ASSERT_EQ(bad.size(), 1u);
    ASSERT_EQ(good.size(), 1u);
    EXPECT_EQ(setting(ours.summary, "length_scale").substr(0, 2), "20");
    // Unscaled: the step's travel (13 mm) is under the TOI target (15 mm), so
    // the ball sinks 5-9 mm into the floor and bounces a step late.
    EXPECT_LT(bad[0].min_height(), s.radius - 0.004);
    EXPECT_GE(bad[0].after.t - good[0].after.t, s.dt - 1e-9);
    // Scaled: TOI stops it within 3 slop / 20 = 0.75 mm, and the bounce is in
    // the step that contains exact's contact (give or take the symplectic
    // Euler lead of g dt t / 2 = 6 mm, 15 ms, at this dt).
    EXPECT_GT(good[0].min_height(), s.radius - 0.001);
    double t_exact = 0;
    for (const WallContact& c : exact.contacts())
        if (c.axis == 1 && c.side < 0) {
            t_exact = c.t;
            break;
        }
    ASSERT_GT(t_exact, 0);
    EXPECT_NEAR(good[0].after.t, t_exact, s.dt);
}

// Sleeping: a body slower than 1 cm/s (engine) for 0.5 s freezes.
TEST(Box2dTrap, Sleeping) {
    Scenario s = seed("seed-2d.toml");
    s.position = {0.5, 0.5, 0};
    s.velocity = {0.0004, 0, 0};  // 8 mm/s in the engine
    s.gravity = {0, 0, 0};
    s.dt = 0.01;
    s.duration = 2.0;
    const double x_exact = 0.5 + 0.0004 * 2.0;
    box2d::Tuning sleepy;
    sleepy.allow_sleep = true;
    const Box2dRun asleep = run_box2d(s, sleepy);
    EXPECT_EQ(asleep.summary.final_state.v.x(), 0.0);
    EXPECT_LT(asleep.summary.final_state.p.x(), x_exact - 0.0005);
    const Box2dRun ours = run_box2d(s);
    EXPECT_EQ(setting(ours.summary, "sleeping"), "off (world and body)");
    EXPECT_NEAR(ours.summary.final_state.v.x(), 0.0004, 1e-9);
    // Float positions near 10 m (engine): 200 steps of half an ulp (4.8e-7 m
    // engine, 2.4e-8 m here) each.
    EXPECT_NEAR(ours.summary.final_state.p.x(), x_exact, 1e-5);
}

// Continuous physics (time of impact against the static walls).
TEST(Box2dTrap, ContinuousCollision) {
    Scenario s = seed("seed-2d.toml");  // dt = 0.03
    s.duration = 5.0;
    box2d::Tuning discrete;
    discrete.continuous = false;
    const auto bad = floor_hits(run_box2d(s, discrete).states, s.radius);
    const Box2dRun ours = run_box2d(s);
    const auto good = floor_hits(ours.states, s.radius);
    ASSERT_EQ(bad.size(), 1u);
    ASSERT_EQ(good.size(), 1u);
    EXPECT_EQ(setting(ours.summary, "ccd").substr(0, 2), "on");
    // Without it the ball sinks 9 mm (a step's travel) and turns a step late.
    EXPECT_LT(bad[0].min_height(), s.radius - 0.005);
    EXPECT_GT(good[0].min_height(), s.radius - 0.001);
    EXPECT_GT(bad[0].after.t, good[0].after.t);
}

// Velocity iterations: friction is capped by the previous iteration's normal
// impulse, so one iteration gives no friction at a new contact.
TEST(Box2dTrap, VelocityIterations) {
    const Scenario s = friction_drop(0.05);
    auto dvx = [&](const box2d::Tuning& t) {
        const auto hits = floor_hits(run_box2d(s, t).states, s.radius);
        EXPECT_EQ(hits.size(), 1u);
        return hits.empty() ? -1.0 : hits[0].before.v.x() - hits[0].after.v.x();
    };
    box2d::Tuning one;
    one.velocity_iterations = 1;
    EXPECT_EQ(dvx(one), 0.0);
    const double ours = dvx({});
    EXPECT_GT(ours, 0.02);
    box2d::Tuning many;
    many.velocity_iterations = 30;
    EXPECT_NEAR(dvx(many), ours, 1e-7);  // 8 has converged
    EXPECT_EQ(setting(run_box2d(s).summary, "velocity_iterations"), "8");
    EXPECT_EQ(setting(run_box2d(s).summary, "position_iterations"), "3 (TOI solve: 20, fixed)");
}

// Warm starting (Box2D's default, kept): with one contact point it changes
// nothing measurable, normal or tangential.
TEST(Box2dTrap, WarmStartingIsHarmless) {
    box2d::Tuning cold;
    cold.warm_starting = false;
    for (const Scenario& s : {friction_drop(0.05), friction_drop(1.0)}) {
        const auto warm = floor_hits(run_box2d(s).states, s.radius);
        const auto cool = floor_hits(run_box2d(s, cold).states, s.radius);
        ASSERT_EQ(warm.size(), 1u);
        ASSERT_EQ(cool.size(), 1u);
        EXPECT_NEAR(warm[0].after.v.x(), cool[0].after.v.x(), 1e-6);
        EXPECT_NEAR(warm[0].after.v.y(), cool[0].after.v.y(), 1e-6);
    }
    EXPECT_EQ(setting(run_box2d(friction_drop(0.05)).summary, "warm_starting"), "on");
}

// Rotation: free (rolls: a disc keeps 2/3 of its speed) or locked (fixedRotation).
TEST(Box2dTrap, Rotation) {
    auto vx_after = [&](bool free_rotation) {
        const Scenario s = friction_drop(1.0, free_rotation);
        const auto hits = floor_hits(run_box2d(s).states, s.radius);
        EXPECT_EQ(hits.size(), 1u);
        return hits.empty() ? -1.0 : hits[0].after.v.x();
    };
    EXPECT_NEAR(vx_after(true), 0.1 * 2.0 / 3.0, 1e-4);
    EXPECT_NEAR(vx_after(false), 0.0, 1e-6);
}

// The per-contact hook: beta once when a contact begins with the ball moving
// into the wall, never while it lasts, not for the ceiling touched at rest at t = 0.
// seed-2d's ball starts at rest against the ceiling, gravity pulling it away:
// not a contact for the law (see moves_into_wall).
TEST(Box2dPerContact, StartingAtRestAgainstTheCeilingIsNotAContact) {
    Scenario s = seed("seed-2d.toml");
    s.duration = 0.3;
    EngineOptions opt;
    opt.tangential_model = TangentialModel::per_contact;
    s.engines["box2d"] = opt;
    const Box2dRun run = run_box2d(s);
    EXPECT_NEAR(run.states.back().v.x(), 0.3, 1e-6);  // Box2D keeps float state
}

TEST(Box2dPerContact, BetaOncePerContact) {
    Scenario s = with_per_contact(seed("seed-2d.toml"));
    s.dt = 1e-3;
    s.duration = 5.0;  // right wall at 1.5 s, floor at 4.28 s
    const ExactModel exact(s);
    const Box2dRun r = run_box2d(s);
    ASSERT_EQ(r.summary.status, RunStatus::ok);
    EXPECT_EQ(setting(r.summary, "tangential_model"), "per-contact");
    EXPECT_EQ(setting(r.summary, "friction"), "ball 0 walls 0");
    auto at = [&](double t) {
        return *std::min_element(r.states.begin(), r.states.end(), [&](const State& a, const State& b) {
            return std::abs(a.t - t) < std::abs(b.t - t);
        });
    };
    const double vx0 = static_cast<float>(0.3 * 20) / 20.0;
    EXPECT_NEAR(at(1.4).v.x(), vx0, 1e-7);  // ceiling contact at t = 0 not counted
    // After the right wall: normal -alpha, tangential beta, as exact.
    const double g_dt = std::abs(s.gravity.y()) * s.dt;
    EXPECT_NEAR(at(2.0).v.x(), exact.state_at(2.0).v.x(), 1e-6);
    EXPECT_NEAR(at(2.0).v.y(), exact.state_at(2.0).v.y(), 2 * g_dt);
    // After the floor contact: beta once (a hook firing every step of the
    // contact, or at every solver pass, would compound it).
    EXPECT_NEAR(at(4.8).v.x(), -0.8 * 0.99 * vx0, 1e-6);
    EXPECT_NEAR(at(4.8).v.x(), exact.state_at(4.8).v.x(), 1e-6);
}

}  // namespace
}  // namespace bouncecheck

namespace bouncecheck {
namespace {

// Box2D 2.4.1's testbed scene testbed/tests/restitution.cpp: radius-1 balls
// dropped from y = 20 onto a ground edge at y = 0, gravity -10, 60 Hz,
// restitution {0, 0.1, 0.3, 0.5, 0.75, 0.9, 1} with restitutionThreshold 10.
// The scene asserts nothing; the rule it shows is b2_contact_solver.cpp's
// `if (vRel < -threshold) velocityBias = -restitution * vRel`, with vRel the
// approach speed after the step's gravity: the rebound is exactly
// -e (v_before + g dt), in float. And, as the scene says, "even with a
// restitution of 1.0, there is some energy change due to position correction":
// the apex after an e = 1 bounce is not the drop height.
TEST(Box2dOwnTests, RestitutionSceneReboundIsMinusEOfTheApproachSpeed) {
    const double g = 10.0, dt = 1.0 / 60.0;
    for (const double e : {0.0, 0.1, 0.3, 0.5, 0.75, 0.9, 1.0}) {
        const Scenario sc = test::make_scenario(2, Vec3(80, 40, 0), 1.0, Vec3(40, 20, 0), Vec3::Zero(),
                                                Vec3(0, -g, 0), e, 1.0, 4.0, dt);
        const auto r = test::run_simulator("box2d", sc);
        ASSERT_EQ(r.summary.status, RunStatus::ok) << r.summary.reason;
        std::size_t k = 1;
        while (k < r.states.size() && r.states[k].v.y() < 0 && r.states[k].v.y() <= r.states[k - 1].v.y()) ++k;
        ASSERT_LT(k, r.states.size()) << "e = " << e << ": no bounce";
        const double approach = r.states[k - 1].v.y() - g * dt;  // after the step's gravity, as the solver sees it
        const double rebound = r.states[k].v.y();
        std::printf("e = %g: approach %.7g m/s, rebound %.7g m/s, ratio %.7g\n", e, approach, rebound,
                    -rebound / approach);
        EXPECT_LT(approach, -10.0) << "above the scene's restitution threshold";
        EXPECT_NEAR(rebound, -e * approach, 2e-6 * std::abs(approach)) << "e = " << e;  // float
        if (e == 1.0) {
            ASSERT_GE(r.summary.apexes.size(), 2u);
            EXPECT_GT(std::abs(r.summary.apexes[1].height - 20.0), 1e-3) << r.summary.apexes[1].height;
        }
    }
}

}  // namespace
}  // namespace bouncecheck
