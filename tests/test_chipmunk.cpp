// The Chipmunk2D 7.0.3 adapter: against the exact model, inside the room, at
// the seed's dt, and one test per trap (Chipmunk's default restored through
// chipmunk::Tuning, its physical consequence measured next to the adapter's
// choice).
#include "engines/chipmunk/chipmunk_adapter.h"
#include "engines/engine.h"
#include "exact/exact_model.h"
#include "metrics/summary.h"
#include "scenarios/loader.h"
#include "tests/support/cli.h"
#include "tests/support/engine_run.h"
#include "tests/support/engine_tests.h"
#include "tests/support/scenarios.h"

#include <chipmunk/chipmunk.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

namespace bouncecheck {
namespace {

namespace fs = std::filesystem;
using test::FloorHit;
using test::first_exact_floor_contact;
using test::floor_hits;
using test::setting;
using test::setting_why;
using ChipmunkRun = test::SimulatorRun;

Scenario seed(const char* name) { return test::bundled_seed(name); }

ChipmunkRun run_chipmunk(const Scenario& s, const chipmunk::Tuning& tuning = {}) {
    return test::record_states(*chipmunk::make_simulator(tuning), s);
}

EngineOptions per_contact_options() {
    EngineOptions o;
    o.tangential_model = TangentialModel::per_contact;
    return o;
}

Scenario with_per_contact(Scenario s) {
    s.engines["chipmunk"] = per_contact_options();
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
    s.engines["chipmunk"] = o;
    return s;
}

// The seed's ball resting on the floor, sliding at `vx`.
Scenario slide(double vx, const EngineOptions& options) {
    Scenario s = seed("seed-2d.toml");
    s.position = {0.2, 0.05, 0};
    s.velocity = {vx, 0, 0};
    s.dt = 0.01;
    s.duration = 5.0;
    s.engines["chipmunk"] = options;
    return s;
}

// The world stepped bare (no recorder: a ball beyond a wall does not stop
// it), `steps` engine steps; returns every state.
std::vector<State> step_bare(const Scenario& s, const chipmunk::Tuning& tuning, int steps) {
    std::vector<Setting> settings;
    const auto world = chipmunk::build_world(s, s.engine_options("chipmunk"), tuning, settings);
    std::vector<State> out;
    for (int i = 0; i < steps; ++i) {
        world->step();
        State st;
        world->read(st);
        st.t = (i + 1) * s.dt;
        out.push_back(st);
    }
    return out;
}

// ---------------------------------------------------------------- capabilities

TEST(ChipmunkCapabilities, TwoDimensionalDoubleEngine) {
    const auto sim = chipmunk::make_simulator({});
    const auto* engine = dynamic_cast<const EngineSimulator*>(sim.get());
    ASSERT_NE(engine, nullptr);
    EXPECT_EQ(sim->name(), "chipmunk");
    const EngineCapabilities caps = engine->capabilities();
    EXPECT_FALSE(caps.runs_3d);
    EXPECT_TRUE(caps.runs_2d);
    EXPECT_TRUE(caps.per_contact_hook);
    EXPECT_EQ(caps.precision, "double");

    Scenario s = seed("seed-2d.toml");
    s.duration = 0.3;
    const ChipmunkRun r = run_chipmunk(s);
    EXPECT_EQ(setting(r.summary, "engine").substr(0, 16), "Chipmunk2D 7.0.3");
    EXPECT_EQ(setting(r.summary, "precision").substr(0, 6), "double");
    EXPECT_EQ(setting(r.summary, "ccd").substr(0, 4), "none");
    // Free flight in x is explicit Euler in doubles, bit for bit: x += 0.3 dt
    // (a float library would round every x to 24 bits).
    double x = s.position.x();
    for (std::size_t i = 1; i < r.states.size(); ++i) {
        x += s.velocity.x() * s.dt;
        ASSERT_EQ(r.states[i].p.x(), x) << "step " << i;
    }
    EXPECT_NE(x, static_cast<double>(static_cast<float>(x)));
}

TEST(ChipmunkCapabilities, Seed3dIsSkippedThroughTheRegistry) {
    const auto sim = test::find_simulator("chipmunk");
    const auto why = sim->cannot_run(seed("seed-3d.toml"));
    ASSERT_TRUE(why.has_value());
    EXPECT_NE(why->find("2D"), std::string::npos) << *why;
    EXPECT_FALSE(sim->cannot_run(seed("seed-2d.toml")).has_value());
    EXPECT_FALSE(sim->cannot_run(with_per_contact(seed("seed-2d.toml"))).has_value());
}

TEST(ChipmunkCapabilities, CliRunsSeed3dWithChipmunkSkipped) {
    const fs::path out = fs::temp_directory_path() / ("bouncecheck-chipmunk-cli-" + std::to_string(::getpid()));
    fs::remove_all(out);
    const test::CliResult r = test::bouncecheck(std::string("run ") + BOUNCECHECK_SCENARIO_DIR +
                                                "/seed-3d.toml --engines reference,exact,chipmunk --out " +
                                                out.string());
    ASSERT_EQ(r.status, 0) << r.output;
    const auto report = nlohmann::json::parse(test::slurp(out / "report.json"));
    ASSERT_EQ(report["scenarios"].size(), 1u);
    const auto& sims = report["scenarios"][0]["simulators"];
    ASSERT_EQ(sims.size(), 3u);
    EXPECT_EQ(sims[2]["simulator"], "chipmunk");
    EXPECT_EQ(sims[2]["status"], "skipped");
    EXPECT_NE(sims[2]["reason"].get<std::string>().find("2D"), std::string::npos) << sims[2].dump();
    fs::remove_all(out);
}

// Debian's libchipmunk is a debug build: the first cpSpaceInit of a process
// prints a banner to stdout. The adapter takes it once, captured, so neither
// the isolated children of `run` nor an in-process run write it.
TEST(ChipmunkCapabilities, DebugBannerStaysOffStdout) {
    const fs::path out = fs::temp_directory_path() / ("bouncecheck-chipmunk-banner-" + std::to_string(::getpid()));
    for (const char* mode : {"", " --in-process"}) {
        fs::remove_all(out);
        // Limits wide enough for any mu the file carries: this test is about the output.
        const test::CliResult r = test::bouncecheck(
            std::string("run ") + BOUNCECHECK_SCENARIO_DIR + "/seed-2d.toml --engines chipmunk --out " +
            out.string() + " --threshold trajectory_rms=10 --threshold trajectory_max=10" + mode);
        ASSERT_EQ(r.status, 0) << r.output;
        EXPECT_EQ(r.output.find("Initializing cpSpace"), std::string::npos) << r.output;
        EXPECT_EQ(r.output.find("NDEBUG"), std::string::npos) << r.output;
        const auto report = nlohmann::json::parse(test::slurp(out / "report.json"));
        const auto& sim = report["scenarios"][0]["simulators"][0];
        std::string debug;
        for (const auto& kv : sim["settings"])
            if (kv["key"] == "debug_build") debug = kv["value"].get<std::string>();
        // Either the banner was taken (a debug build, Debian's) or there was none.
        EXPECT_TRUE(debug.rfind("yes: cpSpaceInit printed \"Initializing cpSpace", 0) == 0 ||
                    debug.rfind("no banner", 0) == 0)
            << debug;
    }
    fs::remove_all(out);
}

// Two worlds stepped at the same time on two threads give the same states,
// bit for bit, as one after the other (no shared state in the library once
// the banner is taken).
TEST(ChipmunkCapabilities, TwoWorldsOnTwoThreadsMatchSerial) {
    const Scenario a = seed("seed-2d.toml");
    const Scenario b = with_per_contact(seed("seed-2d.toml"));
    const ChipmunkRun serial_a = run_chipmunk(a), serial_b = run_chipmunk(b);
    ChipmunkRun parallel_a, parallel_b;
    std::thread ta([&] { parallel_a = run_chipmunk(a); });
    std::thread tb([&] { parallel_b = run_chipmunk(b); });
    ta.join();
    tb.join();
    ASSERT_EQ(parallel_a.states.size(), serial_a.states.size());
    ASSERT_EQ(parallel_b.states.size(), serial_b.states.size());
    for (std::size_t i = 0; i < serial_a.states.size(); ++i) {
        ASSERT_EQ(parallel_a.states[i].p, serial_a.states[i].p) << i;
        ASSERT_EQ(parallel_b.states[i].p, serial_b.states[i].p) << i;
    }
}

// ---------------------------------------------------------------- against exact

// seed-2d with per-contact damping (the law's beta inside the engine) at dt = 1e-3.
TEST(ChipmunkVsExact, FirstFloorContactApexesAndRestitution) {
    Scenario s = with_per_contact(seed("seed-2d.toml"));
    s.dt = 1e-3;
    s.duration = 19.5;  // past the fourth apex (the initial one and three bounces)
    const ExactModel exact(s);
    const ChipmunkRun r = run_chipmunk(s);
    ASSERT_EQ(r.summary.status, RunStatus::ok) << r.summary.reason;

    const auto hits = floor_hits(r.states, s.radius);
    ASSERT_GE(hits.size(), 3u);
    const double t_exact = first_exact_floor_contact(exact, 1);
    ASSERT_GT(t_exact, 0);
    // The first sample after the contact: the step that carries the ball into
    // the floor bounces it, so it lies within one step of exact's contact
    // (explicit Euler's lag over 4.3 s is well under a step here).
    EXPECT_NEAR(hits[0].after.t, t_exact, s.dt);
    EXPECT_NEAR(hits[0].after.t, t_exact, 0.01 * t_exact);  // the acceptance criterion: 1%

    // Apexes: the initial one and three after bounces, within 0.3 mm of exact
    // (measured: 0.05 mm; the acceptance criterion is 3%).
    ASSERT_GE(r.summary.apexes.size(), 4u);
    ASSERT_GE(exact.apexes().size(), 4u);
    for (int i = 0; i < 4; ++i) {
        EXPECT_NEAR(r.summary.apexes[i].height, exact.apexes()[i].height, 3e-4) << "apex " << i;
        EXPECT_NEAR(r.summary.apexes[i].height, exact.apexes()[i].height, 0.03 * exact.apexes()[i].height);
    }
    EXPECT_LT(r.summary.max_penetration, 2e-3);  // the acceptance criterion: 2 mm

    // Restitution: Chipmunk bounces the velocity from before the step's
    // gravity (the sample before the contact): outgoing = alpha x incoming
    // sample, to round-off.
    EXPECT_NEAR(hits[0].after.v.y(), -s.alpha * hits[0].before.v.y(), 1e-12);
    // And the tangential velocity was scaled by beta once (per-contact hook).
    EXPECT_NEAR(hits[0].after.v.x(), s.beta * hits[0].before.v.x(), 1e-12);
}

// Which velocity the measured alpha reads: the recorder's incoming velocity
// is the sample before plus one step of gravity; Chipmunk bounces the sample
// before. At the floor that reads alpha |v| / (|v| + |g| dt); at a side wall,
// where gravity is tangential, alpha exactly.
TEST(ChipmunkVsExact, MeasuredAlphaReadsThePreGravityVelocity) {
    Scenario s = with_per_contact(seed("seed-2d.toml"));  // dt = 0.03
    s.duration = 12.0;  // right wall at 1.5 s, floor at 4.32 s and 11.16 s
    const ChipmunkRun r = run_chipmunk(s);
    const double g_dt = std::abs(s.gravity.y()) * s.dt;
    int floors = 0, sides = 0;
    for (const ContactEvent& c : r.summary.contact_events) {
        if (c.axis == 1 && c.side < 0) {
            const double v_before = c.normal_speed_in - g_dt;  // the sample before the contact
            EXPECT_NEAR(c.normal_coefficient, s.alpha * v_before / (v_before + g_dt), 1e-9) << "t " << c.t;
            EXPECT_LT(c.normal_coefficient, s.alpha - 0.004);
            ++floors;
        } else if (c.axis == 0) {
            EXPECT_NEAR(c.normal_coefficient, s.alpha, 1e-12) << "t " << c.t;
            ++sides;
        }
    }
    EXPECT_GE(floors, 2);
    EXPECT_GE(sides, 1);
}

TEST(ChipmunkVsExact, BallStaysWithinAStepOfTheWalls) {
    for (const double dt : {0.03, 1e-3}) {
        Scenario s = seed("seed-2d.toml");
        s.dt = dt;
        s.duration = dt > 0.01 ? 50.0 : 12.0;
        const ChipmunkRun r = run_chipmunk(s);
        ASSERT_EQ(r.summary.status, RunStatus::ok) << r.summary.reason;
        // No continuous collision: the ball goes as deep as one step carries
        // it beyond the wall (at most 0.45 m/s x dt), then is pushed out.
        const double step = 0.45 * dt;
        EXPECT_GT(r.summary.max_penetration, 0.1 * step) << dt;
        EXPECT_LT(r.summary.max_penetration, step) << dt;
    }
}

TEST(ChipmunkSeed, Seed2dAtSeedDtBounces) {
    const Scenario s = seed("seed-2d.toml");
    const auto run = test::run_simulator("chipmunk", s);
    ASSERT_EQ(run.summary.status, RunStatus::ok) << run.summary.reason;
    EXPECT_EQ(run.summary.steps, 1667);
    EXPECT_GE(run.summary.floor_contacts, 5);
    ASSERT_GE(run.summary.apexes.size(), 5u);
    for (std::size_t i = 1; i < 5; ++i) EXPECT_LT(run.summary.apexes[i].height, run.summary.apexes[i - 1].height);
    const auto pc = test::run_simulator("chipmunk", with_per_contact(s));
    ASSERT_EQ(pc.summary.status, RunStatus::ok) << pc.summary.reason;
    EXPECT_GE(pc.summary.floor_contacts, 5);
}

// ---------------------------------------------------------------- traps

// A new shape has elasticity 0 and friction 0, and a contact's values are the
// products of its two shapes'.
TEST(ChipmunkTrap, ShapeDefaultsAndProductCombine) {
    const double mu = 0.05;
    const Scenario s = friction_drop(mu);
    struct Hit {
        double restitution, mu;
    };
    // The first floor contact (a dead ball's stream shows it settling after).
    auto hit = [&](const chipmunk::Tuning& t) {
        const auto hits = floor_hits(run_chipmunk(s, t).states, s.radius);
        EXPECT_FALSE(hits.empty());
        if (hits.empty()) return Hit{-1, -1};
        const FloorHit& h = hits[0];
        // Sliding throughout: the friction impulse is mu x the normal impulse.
        return Hit{h.restitution(), (h.before.v.x() - h.after.v.x()) / (h.after.v.y() - h.before.v.y())};
    };
    const Hit ours = hit({});
    EXPECT_NEAR(ours.restitution, 0.8, 1e-3);  // alpha x 1 (a step of gravity: 2e-4)
    EXPECT_NEAR(ours.mu, mu, 1e-4);
    const ChipmunkRun run = run_chipmunk(s);
    EXPECT_EQ(setting(run.summary, "elasticity"), "ball 0.8 walls 1");
    EXPECT_EQ(setting(run.summary, "friction"), "ball 0.05 walls 1");

    chipmunk::Tuning defaults;  // Chipmunk's new-shape values on the walls
    defaults.wall_elasticity = 0.0;
    defaults.wall_friction = 0.0;
    const Hit dead = hit(defaults);
    EXPECT_LT(std::abs(dead.restitution), 1e-12);  // no bounce at all
    EXPECT_LT(std::abs(dead.mu), 1e-12);           // and no friction

    chipmunk::Tuning both;  // both shapes given the coefficient (Box2D's way): squared
    both.wall_elasticity = 0.8;
    both.wall_friction = mu;
    const Hit squared = hit(both);
    EXPECT_NEAR(squared.restitution, 0.64, 1e-3);
    EXPECT_NEAR(squared.mu, mu * mu, 1e-4);
}

// collisionSlop defaults to 0.1 (space units): an overlap below it is never
// pushed out. A dead ball (alpha = 0) slammed into the floor at 1 m/s sinks a
// step (3 cm) and stays there; with slop 0 the bias lifts it out.
TEST(ChipmunkTrap, CollisionSlop) {
    Scenario s = seed("seed-2d.toml");
    s.position = {0.5, 0.05, 0};
    s.velocity = {0, -1.0, 0};
    s.alpha = 0.0;
    s.duration = 3.0;
    chipmunk::Tuning slop;
    slop.collision_slop = 0.1;
    const ChipmunkRun bad = run_chipmunk(s, slop);
    const ChipmunkRun ours = run_chipmunk(s);
    EXPECT_EQ(setting(ours.summary, "collision_slop"), "0 m");
    EXPECT_GT(bad.summary.max_penetration, 0.025);
    EXPECT_GT(ours.summary.max_penetration, 0.025);  // the same first step: no CCD
    // Three seconds later: still 3 cm (60% of the radius) inside the floor.
    EXPECT_LT(bad.states.back().p.y(), s.radius - 0.025);
    EXPECT_NEAR(ours.states.back().p.y(), s.radius, 1e-4);
}

// collisionBias: the adapter keeps Chipmunk's default (10% of the overlap per
// 1/60 s). Full correction in one step (0) puts a bounced ball back on the
// surface at once, as the document's clamp does, but a ball at rest then
// hops off the floor and back every few steps: every hop is a new contact,
// and the per-contact hook damps a slide the law leaves alone.
TEST(ChipmunkTrap, CollisionBias) {
    {
        // The default is the library's own value.
        (void)chipmunk::make_simulator({});  // the banner is taken before this space is made
        cpSpace* space = cpSpaceNew();
        EXPECT_EQ(chipmunk::Tuning{}.collision_bias, cpSpaceGetCollisionBias(space));
        cpSpaceFree(space);
    }
    const Scenario s = slide(0.1, per_contact_options());
    const ExactModel exact(s);
    chipmunk::Tuning full;
    full.collision_bias = 0.0;
    const ChipmunkRun hops = run_chipmunk(s, full);
    const ChipmunkRun ours = run_chipmunk(s);
    EXPECT_EQ(setting(ours.summary, "collision_bias").substr(0, 10), "0.00179701");
    EXPECT_NEAR(exact.state_at(s.duration).v.x(), 0.1, 1e-12);  // the law: a slide goes on
    // Ours: beta once, when the ball first presses on the floor, then one
    // contact that lasts.
    EXPECT_NEAR(ours.states.back().v.x(), 0.099, 1e-9);
    EXPECT_LT(ours.summary.contacts, 20);  // the stream sees the first landing's decaying bounce
    // Full correction: 0.1 -> 0.019 m/s in 5 s (a contact every 3 steps).
    EXPECT_LT(hops.states.back().v.x(), 0.03);
    EXPECT_GT(hops.summary.contacts, 100);
}

// Chipmunk's own default bias also keeps the seed's bounces closest to
// exact: at dt = 0.03 the fifth floor contact is 0.15 s late, against 0.33 s
// with full correction (the document's clamp, whose reference is 0.66 s late).
TEST(ChipmunkTrap, CollisionBiasOnTheSeed) {
    Scenario s = with_per_contact(seed("seed-2d.toml"));
    s.duration = 25.0;
    const ExactModel exact(s);
    std::vector<double> t_exact;
    for (const WallContact& c : exact.contacts())
        if (c.axis == 1 && c.side < 0) t_exact.push_back(c.t);
    ASSERT_GE(t_exact.size(), 5u);
    auto fifth_floor_contact = [&](const chipmunk::Tuning& t) {
        const auto hits = floor_hits(run_chipmunk(s, t).states, s.radius);
        EXPECT_GE(hits.size(), 5u);
        return hits.size() < 5 ? 1e9 : hits[4].after.t;
    };
    chipmunk::Tuning full;
    full.collision_bias = 0.0;
    EXPECT_LT(fifth_floor_contact({}) - t_exact[4], 0.2);
    EXPECT_GT(fifth_floor_contact(full) - t_exact[4], 0.3);
}

// Iterations: Chipmunk bounds a contact's friction by the normal impulse of
// the same iteration, so one iteration already gives a single contact its
// full Coulomb friction (Box2D needs two); the default 10 changes nothing.
TEST(ChipmunkTrap, IterationsConvergeAtOne) {
    const Scenario s = friction_drop(0.05);
    auto after = [&](const chipmunk::Tuning& t) {
        const auto hits = floor_hits(run_chipmunk(s, t).states, s.radius);
        EXPECT_EQ(hits.size(), 1u);
        return hits.empty() ? State{} : hits[0].after;
    };
    chipmunk::Tuning one;
    one.iterations = 1;
    const State ours = after({});
    EXPECT_GT(s.velocity.x() - ours.v.x(), 0.02);  // friction acted
    EXPECT_NEAR(after(one).v.x(), ours.v.x(), 1e-12);
    EXPECT_NEAR(after(one).v.y(), ours.v.y(), 1e-12);
    EXPECT_EQ(setting(run_chipmunk(s).summary, "iterations"), "10");
}

// collisionPersistence (3, kept): a contact resuming within 3 steps starts
// from its old accumulated impulse (cpArbiterUpdate copies it; the first
// step does not apply it, and the solver's clamp then works from it). A ball
// against static walls only resumes a contact moving into the wall, where
// this gives the same impulse up to round-off: 1 and 3 run the same bit for
// bit until the ball is at rest (step ~1270 of 1667 at dt 0.03), and within
// 1e-17 after.
TEST(ChipmunkTrap, CollisionPersistenceIsHarmless) {
    for (const Scenario& base : {seed("seed-2d.toml"), with_per_contact(seed("seed-2d.toml"))}) {
        Scenario s = base;
        s.engines["chipmunk"].friction = 0.01;
        chipmunk::Tuning one;
        one.collision_persistence = 1;
        const ChipmunkRun a = run_chipmunk(s), b = run_chipmunk(s, one);
        ASSERT_EQ(a.states.size(), b.states.size());
        for (std::size_t i = 0; i < a.states.size(); ++i) {
            if (i < 1200) {
                ASSERT_EQ(a.states[i].p, b.states[i].p) << i;
                ASSERT_EQ(a.states[i].v, b.states[i].v) << i;
            }
            ASSERT_LT((a.states[i].p - b.states[i].p).norm(), 1e-15) << i;
            ASSERT_LT((a.states[i].v - b.states[i].v).norm(), 1e-15) << i;
        }
        EXPECT_EQ(setting(a.summary, "collision_persistence"), "3 steps");
    }
}

// Damping 1 (Chipmunk's default, set explicitly): pow(1, dt) = 1, and free
// flight is the document's explicit Euler bit for bit (p += v dt, then
// v += g dt). Any other value drags the ball.
TEST(ChipmunkTrap, DampingNoneIsExactExplicitEuler) {
    Scenario s = seed("seed-2d.toml");
    s.position = {0.5, 0.9, 0};
    s.velocity = {0.1, 0.05, 0};
    s.duration = 3.0;  // no contact
    const ChipmunkRun ours = run_chipmunk(s);
    Vec3 p = s.position, v = s.velocity;
    for (std::size_t i = 1; i < ours.states.size(); ++i) {
        p += v * s.dt;
        v += s.gravity * s.dt;
        ASSERT_EQ(ours.states[i].p, p) << i;
        ASSERT_EQ(ours.states[i].v, v) << i;
    }
    EXPECT_EQ(setting(ours.summary, "damping"), "1");
    chipmunk::Tuning drag;
    drag.damping = 0.99;
    EXPECT_LT(run_chipmunk(s, drag).states.back().v.x(), 0.1 * 0.9999);
}

// Sleeping is off by default in Chipmunk (sleepTimeThreshold INFINITY); the
// adapter sets it so. On (0.5 s, Chipmunk's demos), a slow slide freezes: a
// body slower than |g| dt for that long is no longer integrated (its
// velocity is kept, its position stops).
TEST(ChipmunkTrap, Sleeping) {
    const Scenario s = slide(5e-4, EngineOptions{});  // friction mode, mu 0: the slide should go on
    chipmunk::Tuning sleepy;
    sleepy.sleep_time_threshold = 0.5;
    const ChipmunkRun asleep = run_chipmunk(s, sleepy);
    const double x_exact = 0.2 + 5e-4 * asleep.states.back().t;
    EXPECT_LT(asleep.states.back().p.x(), x_exact - 1e-3);
    EXPECT_EQ(asleep.states.back().p.x(), asleep.states[asleep.states.size() / 2].p.x());  // frozen since 2.5 s
    EXPECT_NEAR(asleep.states.back().v.x(), 5e-4, 1e-15);
    const ChipmunkRun ours = run_chipmunk(s);
    EXPECT_EQ(setting(ours.summary, "sleeping"), "off (sleepTimeThreshold INFINITY)");
    EXPECT_NEAR(ours.states.back().v.x(), 5e-4, 1e-12);
    EXPECT_NEAR(ours.states.back().p.x(), x_exact, 1e-9);
}

// Segments collide as capsules: line + radius is the wall. A segment put on
// the wall's line with a radius stops the ball that radius early.
TEST(ChipmunkTrap, SegmentRadius) {
    Scenario s = seed("seed-2d.toml");
    s.dt = 1e-3;
    s.duration = 4.5;  // first floor contact at 4.29 s
    auto lowest_after_4s = [&](const chipmunk::Tuning& t) {
        double low = 1e9;
        for (const State& st : run_chipmunk(s, t).states)
            if (st.t > 4.0) low = std::min(low, st.p.y());
        return low;
    };
    chipmunk::Tuning on_line;
    on_line.wall_radius = 0.01;
    on_line.compensate_wall_radius = false;
    EXPECT_GT(lowest_after_4s(on_line), s.radius + 0.009);
    EXPECT_LT(lowest_after_4s({}), s.radius);
    EXPECT_GT(lowest_after_4s({}), s.radius - 0.0005);
}

// A segment pushes a ball out on the side its centre is on. Thin walls lose a
// fast ball for good; the adapter's walls are thicker than two of the largest
// steps, so the ball comes back.
TEST(ChipmunkTrap, ThickWallsKeepAFastBall) {
    const Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/stress/fast-100.toml");  // 3 m per step
    const int steps = static_cast<int>(std::lround(s.duration / s.dt));
    const auto ours = step_bare(s, {}, steps);
    chipmunk::Tuning thin;
    thin.wall_radius = 0.5;  // half the room
    const auto lost = step_bare(s, thin, steps);
    auto inside = [&](const State& st) {
        return st.p.x() > 0 && st.p.x() < s.room.x() && st.p.y() > 0 && st.p.y() < s.room.y();
    };
    EXPECT_TRUE(inside(ours.back())) << ours.back().p.transpose();
    EXPECT_FALSE(inside(lost.back()));
    EXPECT_GT(lost.back().p.norm(), 100.0);  // still flying away at 100 m/s
}

// No continuous collision detection: a 5 m/s ball lands 6 cm beyond a wall;
// substeps (dt / 8: 1.9 cm of travel) are the remedy.
TEST(ChipmunkTrap, NoContinuousCollisionSubstepsAreTheRemedy) {
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/stress/fast-5.toml");
    s.engines.clear();
    const ChipmunkRun discrete = run_chipmunk(s);
    EXPECT_GT(discrete.summary.max_penetration, s.radius);
    EngineOptions o;
    o.substeps = 8;
    s.engines["chipmunk"] = o;
    const ChipmunkRun sub = run_chipmunk(s);
    EXPECT_LT(sub.summary.max_penetration, 1e-3);
    EXPECT_EQ(setting(sub.summary, "substeps").substr(0, 14), "8 engine steps");
}

// Rotation: free (rolls: a disc keeps 2/3 of its speed) or locked (moment INFINITY).
TEST(ChipmunkTrap, Rotation) {
    auto vx_after = [&](bool free_rotation) {
        const Scenario s = friction_drop(1.0, free_rotation);
        const auto hits = floor_hits(run_chipmunk(s).states, s.radius);
        EXPECT_EQ(hits.size(), 1u);
        return hits.empty() ? -1.0 : hits[0].after.v.x();
    };
    EXPECT_NEAR(vx_after(true), 0.1 * 2.0 / 3.0, 1e-4);
    EXPECT_NEAR(vx_after(false), 0.0, 1e-9);
}

// ---------------------------------------------------------------- per-contact hook

// The hook is beginFunc: once per contact. preSolveFunc runs at every step the
// shapes overlap, and a ball resting on the floor overlaps it for good: beta
// every step stops a slide (0.1 x 0.99^~500).
TEST(ChipmunkPerContact, BeginNotPreSolve) {
    const Scenario s = slide(0.1, per_contact_options());
    chipmunk::Tuning every_step;
    every_step.per_contact_callback = chipmunk::PerContactCallback::pre_solve;
    EXPECT_LT(run_chipmunk(s, every_step).states.back().v.x(), 0.01);
    const ChipmunkRun ours = run_chipmunk(s);
    EXPECT_NEAR(ours.states.back().v.x(), 0.099, 1e-9);
    EXPECT_NE(setting_why(ours.summary, "tangential_model").find("beginFunc"), std::string::npos);
}

// seed-2d's ball starts at rest against the ceiling, gravity pulling it away:
// not a contact for the law (see moves_into_wall).
TEST(ChipmunkPerContact, StartingAtRestAgainstTheCeilingIsNotAContact) {
    Scenario s = with_per_contact(seed("seed-2d.toml"));
    s.duration = 0.3;
    EXPECT_EQ(run_chipmunk(s).states.back().v.x(), 0.3);
}

TEST(ChipmunkPerContact, BetaOncePerContact) {
    Scenario s = with_per_contact(seed("seed-2d.toml"));
    s.dt = 1e-3;
    s.duration = 5.0;  // right wall at 1.5 s, floor at 4.29 s
    const ExactModel exact(s);
    const ChipmunkRun r = run_chipmunk(s);
    ASSERT_EQ(r.summary.status, RunStatus::ok);
    EXPECT_EQ(setting(r.summary, "tangential_model"), "per-contact");
    EXPECT_EQ(setting(r.summary, "friction"), "ball 0 walls 1");
    auto at = [&](double t) {
        return *std::min_element(r.states.begin(), r.states.end(), [&](const State& a, const State& b) {
            return std::abs(a.t - t) < std::abs(b.t - t);
        });
    };
    EXPECT_EQ(at(1.4).v.x(), 0.3);  // the ceiling at t = 0 not counted
    // After the right wall: normal -alpha, tangential beta. The beta scales
    // the velocity before the step's gravity (tangential here), so vy leads
    // exact's by (1 - beta) g dt, and the bounce by up to a step.
    const double g_dt = std::abs(s.gravity.y()) * s.dt;
    EXPECT_NEAR(at(2.0).v.x(), exact.state_at(2.0).v.x(), 1e-12);
    EXPECT_NEAR(at(2.0).v.y(), exact.state_at(2.0).v.y(), 2 * g_dt);
    // After the floor contact: beta once (a hook firing at every step of the
    // contact would compound it).
    EXPECT_NEAR(at(4.8).v.x(), -0.8 * 0.99 * 0.3, 1e-12);
    EXPECT_NEAR(at(4.8).v.x(), exact.state_at(4.8).v.x(), 1e-12);
}

}  // namespace
}  // namespace bouncecheck

namespace bouncecheck {
namespace {

// Chipmunk 7.0.3's own test xcode/ObjectiveChipmunkTests/SpaceTest.m
// (testBasicSimulation): gravity -100, a radius-1 ball at (-10, 10) inside
// bounds (-50, 0)-(50, 100), 100 steps of 0.01 s, elasticity 1 x the shape
// default 0 (cpArbiter.c multiplies them). It asserts the ball rests on the
// floor: |y - 1| < 1.1 * collisionSlop (0.1 by default). The adapter's slop
// is its own (docs/engines.md), so its bound is the one the test states.
TEST(ChipmunkOwnTests, BasicSimulationBallRestsOnTheFloor) {
    const Scenario sc = test::make_scenario(2, Vec3(100, 100, 0), 1.0, Vec3(40, 10, 0), Vec3::Zero(),
                                            Vec3(0, -100, 0), 0.0, 1.0, 1.0, 0.01);
    const auto r = test::run_simulator("chipmunk", sc);
    ASSERT_EQ(r.summary.status, RunStatus::ok) << r.summary.reason;
    ASSERT_GE(r.states.size(), 101u);
    const State& after_100_steps = r.states[100];
    std::printf("after 100 steps (t = %.4f s): y = %.9g, v_y = %.3g\n", after_100_steps.t, after_100_steps.p.y(),
                after_100_steps.v.y());
    EXPECT_LT(std::abs(after_100_steps.p.y() - 1.0), 1.1 * 0.1);
    EXPECT_NEAR(after_100_steps.p.x(), 40.0, 1e-9);
}

}  // namespace
}  // namespace bouncecheck
