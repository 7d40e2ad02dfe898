// MuJoCo 2.2.2 adapter: against the exact model, containment, the seeds, the
// planar 2D mapping, the per-contact hook, threads, and one test per trap:
// each restores MuJoCo's default through mujoco::Tuning and measures what it
// does to the ball, next to the chosen setting doing the right thing.
#include "engines/mujoco/mujoco_adapter.h"
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
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

namespace bouncecheck {
namespace {

namespace fs = std::filesystem;
using mujoco::ContactLaw;
using mujoco::Tuning;
using test::setting;
using test::first_exact_floor_contact;
using test::first_floor_event;

// The bundled file's [engines] tables are dropped: each test sets the engine
// options it is about.
Scenario seed(const std::string& file) {
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + file);
    s.engines.clear();
    return s;
}

EngineOptions per_contact_options() {
    EngineOptions o;
    o.tangential_model = TangentialModel::per_contact;
    return o;
}

Scenario variant(Scenario s, double dt, double duration, bool per_contact) {
    s.dt = dt;
    s.duration = duration;
    if (per_contact) s.engines["mujoco"] = per_contact_options();
    return s;
}

// Runs through the simulator's real run() (the shared loop), keeping every state.
struct Outcome {
    SimulatorSummary summary;
    std::vector<State> states;
};
Outcome run(const Scenario& s, const Tuning& tuning = Tuning::chosen()) {
    const auto sim = mujoco::make_simulator(tuning);
    StateVector sink;
    Outcome r;
    r.summary = record_run(*sim, s, &sink);
    r.states = std::move(sink.states);
    return r;
}

// Steps the world directly (the same world run() builds), one state per step.
struct Probe {
    std::vector<State> states;
    std::vector<Setting> settings;
    mujoco::Stats stats;
    std::unique_ptr<mujoco::World> world;
};
Probe probe(const Scenario& s, const Tuning& tuning = Tuning::chosen(), long steps = -1) {
    Probe out;
    out.world = mujoco::build_world(s, s.engine_options("mujoco"), tuning, out.settings);
    State st{0, s.position, s.velocity};
    out.states.push_back(st);
    if (steps < 0) steps = std::llround(s.duration / s.dt);
    for (long k = 1; k <= steps; ++k) {
        out.world->step();
        out.world->read(st);
        st.t = static_cast<double>(k) * s.dt;
        out.states.push_back(st);
    }
    out.stats = out.world->stats();
    return out;
}

// Floor bounces in a state stream: the vertical velocity turns from down to
// not down near the floor. `before` is the last state moving down, `after`
// the first one not.
struct Bounce {
    State before, after;
    double restitution(int z) const { return -after.v[z] / before.v[z]; }
};
std::vector<Bounce> floor_bounces(const Scenario& s, const std::vector<State>& states) {
    const int z = s.vertical_axis();
    std::vector<Bounce> out;
    for (std::size_t k = 1; k < states.size(); ++k)
        if (states[k - 1].v[z] < 0 && states[k].v[z] >= 0 &&
            states[k].p[z] - s.radius <= -states[k - 1].v[z] * s.dt + 0.1 * s.radius)
            out.push_back({states[k - 1], states[k]});
    return out;
}

// A ball at rest `height` above touching the floor of seed-3d's room.
Scenario drop(double height, double dt, double duration, int dim = 3) {
    Scenario s = seed(dim == 3 ? "seed-3d.toml" : "seed-2d.toml");
    s.name = "drop";
    s.position = dim == 3 ? Vec3(0.5, 0.5, s.radius + height) : Vec3(0.5, s.radius + height, 0);
    s.velocity = Vec3::Zero();
    s.dt = dt;
    s.duration = duration;
    return s;
}

// A drop onto the floor while moving sideways, with Coulomb friction mu.
Scenario sliding_drop(int dim, double mu, Vec3 velocity, bool free_rotation = false) {
    Scenario s = drop(0.45, 1e-3, 3.2, dim);
    s.velocity = velocity;
    EngineOptions o;
    o.friction = mu;
    o.free_rotation = free_rotation;
    s.engines["mujoco"] = o;
    return s;
}

// ---------------------------------------------------------------- capabilities

TEST(MujocoCapabilities, DoublePrecisionThreeAndTwoDimensionsParallel) {
    const auto sim = mujoco::make_simulator(Tuning::chosen());
    const auto* engine = dynamic_cast<const EngineSimulator*>(sim.get());
    ASSERT_NE(engine, nullptr);
    EXPECT_EQ(sim->name(), "mujoco");
    const EngineCapabilities caps = engine->capabilities();
    EXPECT_TRUE(caps.runs_3d);
    EXPECT_TRUE(caps.runs_2d);
    EXPECT_TRUE(caps.planar_2d_in_3d);
    EXPECT_TRUE(caps.per_contact_hook);
    EXPECT_EQ(caps.precision, "double");
    const auto registered = test::find_simulator("mujoco");
    EXPECT_FALSE(registered->cannot_run(seed("seed-3d.toml")).has_value());
    EXPECT_FALSE(registered->cannot_run(variant(seed("seed-2d.toml"), 0.03, 1, true)).has_value());
}

// ---------------------------------------------------------------- exact

// The acceptance runs: seed-3d and seed-2d per-contact at dt = 1e-3 against
// exact, through the registered simulator's real path.
TEST(MujocoExact, PerContactSeedsAtSmallStep) {
    for (const char* file : {"seed-3d-per-contact.toml", "seed-2d-per-contact.toml"}) {
        const Scenario s = variant(seed(file), 1e-3, 20.0, true);
        const ExactModel exact(s);
        const auto r = test::run_simulator("mujoco", s);
        ASSERT_EQ(r.summary.status, RunStatus::ok) << file << ": " << r.summary.reason;
        const int z = s.vertical_axis();

        // First floor contact: the stream's reversal sample comes after the
        // step that found the ball inside the floor, up to two steps after
        // exact's instant (one to sink in, one to turn). Required: within 1%.
        const auto t_first = first_floor_event(r.summary, z);
        ASSERT_TRUE(t_first.has_value()) << file;
        const double t_exact = first_exact_floor_contact(exact, z);
        EXPECT_NEAR(*t_first, t_exact, 2.5 * s.dt) << file;
        EXPECT_LT(std::abs(*t_first - t_exact) / t_exact, 0.01) << file;

        // First three apexes: within 3% required; each bounce and flight adds
        // O(u dt) (semi-implicit Euler, the bounce up to a step late):
        // measured within 0.15 mm, so 0.5 mm.
        ASSERT_GE(r.summary.apexes.size(), 3u) << file;
        ASSERT_GE(exact.apexes().size(), 3u) << file;
        for (std::size_t i = 0; i < 3; ++i) {
            const double got = r.summary.apexes[i].height, want = exact.apexes()[i].height;
            EXPECT_NEAR(got, want, 5e-4) << file << " apex " << i;
            EXPECT_LT(std::abs(got - want) / (want - s.radius), 0.03) << file << " apex " << i;
        }

        // Never more than 2 mm beyond a wall: at most one step of travel
        // (0.45 m/s x 1 ms) with the one-step contact.
        EXPECT_LE(r.summary.max_penetration, 2e-3) << file;
        EXPECT_LE(r.summary.max_penetration, 0.5e-3) << file;
    }
}

// The contact law's restitution, measured at the step that turns the ball:
// alpha whatever the depth at which the ball was found (drops from several
// heights put it at different phases of a step). The anchor spring adds
// anchor (phi - 1/2) and the impedance lets 1e-4 of a step's gravity through.
TEST(MujocoExact, RestitutionIsAlphaAtEveryDepth) {
    for (const double height : {0.1, 0.2, 0.3, 0.4, 0.45}) {
        for (const int dim : {2, 3}) {
            const Scenario s = drop(height, 1e-3, 4.0, dim);
            const Probe p = probe(s);
            const auto bounces = floor_bounces(s, p.states);
            ASSERT_FALSE(bounces.empty()) << height;
            const int z = s.vertical_axis();
            const double u = -bounces[0].before.v[z];
            const double tol = Tuning::chosen().damper_anchor * (1 - s.alpha) / 2 + 1e-4 * 0.0981 * s.dt / u + 1e-12;
            EXPECT_NEAR(bounces[0].restitution(z), s.alpha, tol) << "height " << height << " dim " << dim;
            // The contact lasts one step (two when found deeper than alpha u dt).
            const double depth = s.radius - std::min(bounces[0].before.p[z], bounces[0].after.p[z]);
            EXPECT_LE(depth, u * s.dt + 1e-12) << height;
        }
    }
}

// The settings say what was derived and what MuJoCo got.
TEST(MujocoExact, DampingDerivedAndCorrectedAreReported) {
    const Scenario s3 = drop(0.1, 1e-3, 0.01, 3), s2 = drop(0.1, 1e-3, 0.01, 2);
    const auto c3 = mujoco::contact_parameters(s3, Tuning::chosen());
    const auto c2 = mujoco::contact_parameters(s2, Tuning::chosen());
    EXPECT_DOUBLE_EQ(c3.damping_derived, 1.8 / 1e-3);
    // 3D: MuJoCo's 1 / dmax scaling and its regulariser cancel (factor 1);
    // only the anchor's mean kick is taken off.
    EXPECT_NEAR(c3.impedance_factor, 1.0, 1e-15);
    const double anchor = Tuning::chosen().damper_anchor * (1 - 0.8);
    EXPECT_NEAR(c3.damping * 1e-3, 1.8 - anchor / 2, 1e-12);
    EXPECT_NEAR(c3.stiffness * 1e-6, anchor, 1e-15);
    // 2D: MuJoCo's estimate of the inverse mass is 2/3 of the ball's.
    EXPECT_NEAR(c2.impedance_factor, 1 / (0.9999 + 1e-4 * 2.0 / 3.0), 1e-15);
    EXPECT_NEAR(c2.damping * 1e-3 * c2.impedance_factor, 1.8 - anchor / 2, 1e-12);
    const Probe p = probe(s2);
    EXPECT_NE(setting(p.settings, "contact.damping").find("derived b = 1800 1/s"), std::string::npos)
        << setting(p.settings, "contact.damping");
    EXPECT_NE(setting(p.settings, "contact.stiffness_rule").find("anchor"), std::string::npos);
}

// Without the correction the 2D ball bounces at f (1 + alpha) - 1 (f the
// impedance factor 1.0000333): 0.80006 instead of 0.8. Anchor off and no
// gravity, so nothing else moves the number.
TEST(MujocoExact, ImpedanceCorrectionIn2D) {
    Scenario s = drop(0.1, 1e-3, 1.0, 2);
    s.gravity = Vec3::Zero();
    s.velocity = Vec3(0, -0.3, 0);
    auto e = [&](const Tuning& t) {
        const auto b = floor_bounces(s, probe(s, t).states);
        EXPECT_EQ(b.size(), 1u);
        return b.empty() ? -1.0 : b[0].restitution(1);
    };
    Tuning exact_law = Tuning::chosen();
    exact_law.damper_anchor = 0;
    Tuning uncorrected = exact_law;
    uncorrected.correct_for_impedance = false;
    EXPECT_NEAR(e(exact_law), 0.8, 1e-12);
    const double f = 1 / (0.9999 + 1e-4 * 2.0 / 3.0);
    EXPECT_NEAR(e(uncorrected), f * 1.8 - 1, 1e-12);
    EXPECT_GT(e(uncorrected) - 0.8, 5e-5);
}

// ---------------------------------------------------------------- room and seeds

// Both seeds at their dt, both tangential models: the ball never goes
// further beyond a wall than one step of travel, and the run is ok.
TEST(MujocoRoom, BallNeverLeavesTheRoom) {
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        for (const bool per_contact : {false, true}) {
            const Scenario base = seed(file);
            Scenario s = variant(base, base.dt, base.duration, per_contact);
            if (!per_contact) s.engines["mujoco"].friction = 0.01;
            const Outcome r = run(s);
            ASSERT_EQ(r.summary.status, RunStatus::ok) << file << ": " << r.summary.reason;
            double max_speed = 0;
            for (const State& st : r.states) max_speed = std::max(max_speed, st.v.norm());
            EXPECT_LE(r.summary.max_penetration, max_speed * s.dt) << file << " per_contact " << per_contact;
            EXPECT_GT(r.summary.max_penetration, 0.0) << file;  // it does sink: contacts are found inside
        }
    }
}

// The seeds at dt = 0.03: decreasing bounces, and the stream's measured
// restitution, at the impact instant, is alpha to within the one step of
// gravity an engine's samples leave the instant uncertain by, (1 + alpha)
// |g| dt / v (verdicts.h): MuJoCo turns the velocity the step starts from,
// and its ball sits inside the wall when it does. (Measured against the
// sample before plus a step of gravity, the floor read alpha (1 - |g| dt / v).)
TEST(MujocoSeeds, BounceAtTheSeedStep) {
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        const Scenario s = variant(seed(file), 0.03, seed(file).duration, true);
        const Outcome r = run(s);
        ASSERT_EQ(r.summary.status, RunStatus::ok) << file;
        EXPECT_GE(r.summary.floor_contacts, 10) << file;
        ASSERT_GE(r.summary.apexes.size(), 5u) << file;
        for (std::size_t i = 1; i < 5; ++i) EXPECT_LT(r.summary.apexes[i].height, r.summary.apexes[i - 1].height);
        const double g = std::abs(s.gravity[s.vertical_axis()]);
        int checked = 0;
        for (const ContactEvent& e : r.summary.contact_events) {
            if (e.normal_speed_in < 30 * g * s.dt) continue;
            EXPECT_NEAR(e.normal_coefficient, s.alpha, (1 + s.alpha) * g * s.dt / e.normal_speed_in)
                << file << " t " << e.t << " axis " << e.axis;
            ++checked;
        }
        EXPECT_GE(checked, 5) << file;
    }
}

// 2D runs in MuJoCo's x-z plane with no y joint: y never moves; rotation is
// one hinge (free) or none (locked); in 3D a ball joint or none.
TEST(MujocoPlanar, TwoDimensionalRunStaysInItsPlane) {
    Scenario s = seed("seed-2d.toml");
    s.duration = 10;
    s.engines["mujoco"].friction = 0.3;
    const Probe p = probe(s);
    double max_y = 0;
    for (std::size_t k = 0; k < p.states.size(); ++k) max_y = std::max(max_y, std::abs(p.world->engine_position().y()));
    EXPECT_EQ(max_y, 0.0);
    EXPECT_EQ(p.world->rotational_dofs(), 1);
    EXPECT_EQ(p.world->engine_gravity(), Vec3(0, 0, -0.0981));  // scenario y is MuJoCo z
    EXPECT_NEAR(p.world->engine_position().x(), p.states.back().p.x(), 0);
    EXPECT_NEAR(p.world->engine_position().z(), p.states.back().p.y(), 0);
    s.engines["mujoco"].free_rotation = false;
    EXPECT_EQ(probe(s, Tuning::chosen(), 1).world->rotational_dofs(), 0);
    Scenario s3 = seed("seed-3d.toml");
    EXPECT_EQ(probe(s3, Tuning::chosen(), 1).world->rotational_dofs(), 3);
    s3.engines["mujoco"].free_rotation = false;
    EXPECT_EQ(probe(s3, Tuning::chosen(), 1).world->rotational_dofs(), 0);
}

// Rotation takes part in friction: with mu = 1 the free ball spins up and
// keeps more of its sideways speed than the locked one.
TEST(MujocoPlanar, RotationTakesPartInFriction) {
    auto vx_after = [](bool free_rotation) {
        const Scenario s = sliding_drop(2, 1.0, Vec3(0.1, 0, 0), free_rotation);
        const auto b = floor_bounces(s, probe(s).states);
        EXPECT_EQ(b.size(), 1u);
        return b.empty() ? 1e9 : b[0].after.v.x();
    };
    // See MujocoWeakness.StickingContactReversesItsSlip for these numbers.
    EXPECT_NEAR(vx_after(true), 0.1 * (1 - 2.0 / 7.0 * 1.8), 1e-3);
    EXPECT_NEAR(vx_after(false), -0.08, 1e-3);
}

// ---------------------------------------------------------------- per-contact hook

// seed-3d starts touching the back wall, moving into it. MuJoCo sees no
// contact at t = 0 (1 - 0.95 - 0.05 is +4e-17), the ball sinks one step, the
// second step finds it: the hook scales x and z by beta, the solve turns y.
TEST(MujocoPerContact, ScalesTangentialVelocityAtTheContactStep) {
    const Scenario s = variant(seed("seed-3d.toml"), 1e-3, 2e-3, true);
    const Probe p = probe(s);
    ASSERT_EQ(p.states.size(), 3u);
    const State& before = p.states[1];
    const State& after = p.states[2];
    EXPECT_EQ(before.v.x(), 0.3);
    EXPECT_NEAR(after.v.x(), 0.3 * s.beta, 1e-15);
    EXPECT_NEAR(after.v.z(), before.v.z() * s.beta + s.gravity.z() * s.dt, 1e-15);
    EXPECT_NEAR(after.v.y(), -s.alpha * before.v.y(), 1e-4 * std::abs(before.v.y()));
    EXPECT_EQ(p.stats.new_wall_contacts, 1);
    EXPECT_EQ(p.stats.beta_applied, 1);
    // Split step: the Euler update moved the ball with the scaled velocity.
    EXPECT_NEAR(after.p.x(), before.p.x() + s.beta * 0.3 * s.dt, 1e-15);
    EXPECT_NE(setting(p.settings, "tangential_model").find("between mj_step1 and mj_step2"), std::string::npos);
}

// Applied after mj_step instead, beta reaches the same velocity but the step
// that found the contact moved the ball with the unscaled one.
TEST(MujocoPerContact, AfterTheStepTheContactStepMovesUnscaled) {
    const Scenario s = variant(seed("seed-3d.toml"), 1e-3, 2e-3, true);
    Tuning late = Tuning::chosen();
    late.beta_in_split_step = false;
    const Probe p = probe(s, late);
    const State& before = p.states[1];
    const State& after = p.states[2];
    EXPECT_NEAR(after.v.x(), 0.3 * s.beta, 1e-15);
    EXPECT_NEAR(after.p.x(), before.p.x() + 0.3 * s.dt, 1e-15);
    EXPECT_EQ(p.stats.beta_applied, 1);
}

// seed-2d starts at rest against the ceiling, gravity pulling it away: not a
// contact for the law (MuJoCo excludes a contact at distance 0 anyway).
TEST(MujocoPerContact, StartingAtRestAgainstTheCeilingIsNotAContact) {
    const Scenario s = variant(seed("seed-2d.toml"), 0.03, 0.3, true);
    const Probe p = probe(s);
    EXPECT_EQ(p.states.back().v.x(), 0.3);
    EXPECT_EQ(p.stats.beta_applied, 0);
}

// A lasting contact (alpha = 0: the ball slides on the floor, pressed by
// gravity) is one contact: beta once, not once per step.
TEST(MujocoPerContact, LastingContactScalesOnce) {
    Scenario s = variant(drop(0, 0.01, 1.0), 0.01, 1.0, true);
    s.alpha = 0;
    s.position.z() = s.radius - 1e-6;  // found inside the floor at the first step
    s.velocity = Vec3(0.3, 0, 0);
    const Probe p = probe(s);
    EXPECT_EQ(p.stats.new_wall_contacts, 1);
    EXPECT_GE(p.stats.touching_steps, 99);
    EXPECT_NEAR(p.states.back().v.x(), 0.3 * s.beta, 1e-15);
    EXPECT_NEAR(p.states.back().p.z(), s.radius, 1e-5);
}

// ---------------------------------------------------------------- traps

// MuJoCo's default solref (0.02, 1) is critically damped: no bounce. Measured
// second apex 0.062 m instead of exact's 0.619 (seed-2d, dt 1e-3); the ball
// is dead after its first floor contact.
TEST(MujocoTraps, DefaultSolrefKillsTheBounce) {
    const Scenario s = variant(seed("seed-2d.toml"), 1e-3, 12.0, true);
    Tuning dflt = Tuning::chosen();
    dflt.law = ContactLaw::engine_default;
    const Outcome bad = run(s, dflt);
    ASSERT_GE(bad.summary.apexes.size(), 2u);
    EXPECT_LT(bad.summary.apexes[1].height, 0.1);
    EXPECT_EQ(setting(bad.summary.settings, "contact.law").rfind("MuJoCo default", 0), 0u);
    const Outcome good = run(s);
    ASSERT_GE(good.summary.apexes.size(), 2u);
    EXPECT_NEAR(good.summary.apexes[1].height, ExactModel(s).apexes()[1].height, 5e-4);
}

// MuJoCo's default solimp (0.9, 0.95, 0.001, 0.5, 2): the row reaches 90-95%
// of its reference, depending on depth, and 5-10% of gravity leaks in. At
// dt 1e-3 (depths under the 1 mm width) the bounce is 0.92 of alpha:
// measured second apex 0.532 m instead of 0.619, rest 10 s early.
TEST(MujocoTraps, DefaultSolimpWeakensTheBounce) {
    const Scenario s = variant(seed("seed-2d.toml"), 1e-3, 12.0, true);
    Tuning dflt = Tuning::chosen();
    dflt.solimp = {0.9, 0.95, 0.001, 0.5, 2};
    const Probe bad = probe(s, dflt);
    const auto b = floor_bounces(s, bad.states);
    ASSERT_FALSE(b.empty());
    EXPECT_LT(b[0].restitution(1), 0.76);
    EXPECT_GT(b[0].restitution(1), 0.70);
    const auto ok = floor_bounces(s, probe(s).states);
    ASSERT_FALSE(ok.empty());
    EXPECT_NEAR(ok[0].restitution(1), s.alpha, Tuning::chosen().damper_anchor * (1 - s.alpha) / 2 + 1e-6);
}

// opt.timestep defaults to 0.002 s and mj_step advances that, whatever dt the
// loop means: at dt 0.03 the ball runs at 1/15 of its speed.
TEST(MujocoTraps, DefaultTimestepSlowsTime) {
    const Scenario s = variant(seed("seed-3d.toml"), 0.03, 12.0, true);
    Tuning dflt = Tuning::chosen();
    dflt.set_timestep = false;
    const Probe bad = probe(s, dflt, 1);
    EXPECT_EQ(bad.world->engine_timestep(), 0.002);
    EXPECT_TRUE(floor_bounces(s, probe(s, dflt).states).empty());  // exact's first floor contact: 5.66 s
    const auto ok = floor_bounces(s, probe(s).states);
    ASSERT_FALSE(ok.empty());
    EXPECT_NEAR(ok[0].after.t, first_exact_floor_contact(ExactModel(s), 2), 2 * s.dt);
}

// opt.gravity defaults to (0, 0, -9.81): 100x the seeds'.
TEST(MujocoTraps, DefaultGravityIsEarths) {
    const Scenario s = variant(drop(0.2, 0.01, 2.2), 0.01, 2.2, true);
    Tuning dflt = Tuning::chosen();
    dflt.set_gravity = false;
    EXPECT_EQ(probe(s, dflt, 1).world->engine_gravity(), Vec3(0, 0, -9.81));
    const auto bad = floor_bounces(s, probe(s, dflt).states);
    ASSERT_FALSE(bad.empty());
    EXPECT_NEAR(bad[0].after.t, std::sqrt(2 * 0.2 / 9.81), 2 * s.dt);  // 0.20 s
    const auto ok = floor_bounces(s, probe(s).states);
    ASSERT_FALSE(ok.empty());
    EXPECT_NEAR(ok[0].after.t, std::sqrt(2 * 0.2 / 0.0981), 2 * s.dt);  // 2.02 s
}

// A contact takes the larger friction of its two geoms: the walls' default 1
// makes every contact's mu 1 whatever the ball's (measured effective mu 0.34
// on this bounce: the contact sticks, see StickingContactReversesItsSlip).
TEST(MujocoTraps, WallFrictionCombinesAsTheMaximum) {
    const double mu = 0.05;
    const Scenario s = sliding_drop(2, mu, Vec3(0.1, 0, 0));
    auto effective_mu = [&](const Tuning& t) {
        const auto b = floor_bounces(s, probe(s, t).states);
        EXPECT_EQ(b.size(), 1u);
        if (b.empty()) return -1.0;
        return (b[0].before.v.x() - b[0].after.v.x()) / (b[0].after.v.y() - b[0].before.v.y());
    };
    EXPECT_NEAR(effective_mu(Tuning::chosen()), mu, 1e-4);
    Tuning dflt = Tuning::chosen();
    dflt.wall_friction = 1;
    EXPECT_GT(effective_mu(dflt), 5 * mu);
    const Probe p = probe(s, Tuning::chosen(), 1);
    EXPECT_EQ(setting(p.settings, "contact.condim"), "3");
    EXPECT_EQ(setting(p.settings, "contact.friction").rfind("ball 0.050000000000000003 0 0, walls 0.050000000000000003", 0),
              0u);
}

// MuJoCo's default condim 3 with its default friction 1 in per-contact mode:
// the floor contact grips: the sideways speed leaves at 0.048 m/s instead of
// 0.1 beta = 0.099.
TEST(MujocoTraps, DefaultCondimAndFrictionGripInPerContactMode) {
    Scenario s = sliding_drop(2, 0, Vec3(0.1, 0, 0));
    s.engines["mujoco"] = per_contact_options();
    Tuning dflt = Tuning::chosen();
    dflt.condim = 3;
    dflt.wall_friction = 1;
    const auto bad = floor_bounces(s, probe(s, dflt).states);
    ASSERT_EQ(bad.size(), 1u);
    // Measured 0.048 (the free ball spins up; see StickingContactReversesItsSlip).
    EXPECT_LT(bad[0].after.v.x(), 0.6 * 0.1);
    const Probe good = probe(s);
    const auto ok = floor_bounces(s, good.states);
    ASSERT_EQ(ok.size(), 1u);
    EXPECT_NEAR(ok[0].after.v.x(), 0.1 * s.beta, 1e-15);
    EXPECT_EQ(setting(good.settings, "contact.condim"), "1");
}

// The pyramidal cone (MuJoCo's default) bounds the friction along a diagonal
// slip at mu / sqrt(2); the elliptic cone is Coulomb's (3D).
TEST(MujocoTraps, PyramidalConeWeakensDiagonalFriction) {
    const double mu = 0.05;
    const Scenario s = sliding_drop(3, mu, Vec3(0.1, 0.1, 0));
    auto effective_mu = [&](const Tuning& t) {
        const auto b = floor_bounces(s, probe(s, t).states);
        EXPECT_EQ(b.size(), 1u);
        if (b.empty()) return -1.0;
        const Vec3 dv = b[0].after.v - b[0].before.v;
        return std::hypot(dv.x(), dv.y()) / dv.z();
    };
    EXPECT_NEAR(effective_mu(Tuning::chosen()), mu, 1e-4);
    Tuning dflt = Tuning::chosen();
    dflt.cone = mujoco::Cone::pyramidal;
    EXPECT_NEAR(effective_mu(dflt), mu / std::sqrt(2.0), 1e-3);
}

// The damper law is written for one Euler update per step. RK4 solves the
// contact at four stages (each stage's collision at its own position, the
// damper's 1.8 / dt applied to each stage's velocity and averaged): the ball
// never turns, it stops inside the floor. The implicit integrator equals
// Euler here (no velocity-dependent passive force).
TEST(MujocoTraps, RungeKuttaUndoesTheBounce) {
    const Scenario s = variant(drop(0.2, 1e-3, 2.5), 1e-3, 2.5, false);
    Tuning rk4 = Tuning::chosen();
    rk4.integrator = mujoco::Integrator::rk4;
    const Probe bad = probe(s, rk4);
    // After reaching the floor the ball never comes back out of it.
    double deepest = s.radius, highest_after = 0;
    bool reached = false;
    for (const State& st : bad.states) {
        reached = reached || st.p.z() < s.radius;
        if (reached) highest_after = std::max(highest_after, st.p.z());
        deepest = std::min(deepest, st.p.z());
    }
    ASSERT_TRUE(reached);
    EXPECT_LT(highest_after, s.radius);
    EXPECT_LT(deepest, s.radius - 5e-5);  // measured 0.11 mm deep, and it stays in
    Tuning implicit = Tuning::chosen();
    implicit.integrator = mujoco::Integrator::implicit;
    const auto ok = floor_bounces(s, probe(s).states);
    const auto imp = floor_bounces(s, probe(s, implicit).states);
    ASSERT_EQ(ok.size(), 1u);
    ASSERT_EQ(imp.size(), 1u);
    EXPECT_NEAR(imp[0].after.v.z(), ok[0].after.v.z(), 1e-12);
}

// mj_step resets mjData to the model's initial state (qpos0: the ball's
// centre at the room's corner, at rest) on a NaN or a value beyond 1e10, with
// a warning only. The adapter throws (the run fails with MuJoCo's warning
// text as its reason); nothing is printed and no MUJOCO_LOG.TXT is written.
TEST(MujocoTraps, ResetOnBadStateFailsTheRun) {
    Scenario s = drop(0.2, 1e-3, 0.01);
    s.velocity = Vec3(2e10, 0, 0);
    const fs::path dir = fs::temp_directory_path() / ("bouncecheck-mujoco-log-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path cwd = fs::current_path();
    fs::current_path(dir);
    testing::internal::CaptureStdout();
    std::string reason;  // the commands turn the exception into a failed run with this reason
    try {
        run(s);
    } catch (const std::exception& e) {
        reason = e.what();
    }
    const std::string printed = testing::internal::GetCapturedStdout();
    fs::current_path(cwd);
    EXPECT_NE(reason.find("mjWARN_BADQVEL"), std::string::npos) << reason;
    EXPECT_NE(reason.find("Time = 0.0000"), std::string::npos) << reason;  // MuJoCo's own text
    EXPECT_EQ(printed, "");
    EXPECT_FALSE(fs::exists(dir / "MUJOCO_LOG.TXT"));
    fs::remove_all(dir);

    Tuning dflt = Tuning::chosen();
    dflt.fail_on_warning = false;
    const Probe p = probe(s, dflt, 1);
    // Teleported to qpos0 (the room's corner, from (0.5, 0.5, 0.25)), no error.
    EXPECT_LT(p.states[1].p.norm(), 1e-3);
    EXPECT_LT(p.states[1].v.norm(), 1e-2);
}

// ---------------------------------------------------------------- deliberate settings

// The pure damper (anchor 0) lets 1e-4 of gravity through a resting contact:
// the ball sinks at 1e-4 g dt / (1 + alpha) per second forever (1.6 cm in the
// 1e5 s of stress/long-horizon-3d). The anchor spring (k dt^2 = 1e-4 (1 -
// alpha)) holds it at 1e-4 g dt^2 / (k dt^2) below the surface.
TEST(MujocoSettings, AnchorHoldsARestingBall) {
    Scenario s = drop(0, 0.03, 3000.0);
    s.position.z() = s.radius - 1e-9;
    Tuning pure = Tuning::chosen();
    pure.damper_anchor = 0;
    const double leak = 1e-4 * 0.0981 * s.dt / 1.8;  // m/s
    const double sunk = s.radius - probe(s, pure).states.back().p.z();
    EXPECT_NEAR(sunk, leak * s.duration, 0.05 * leak * s.duration);  // 0.49 mm
    // With the anchor the depth approaches 1e-4 g dt^2 / (k dt^2) = 0.44 mm
    // with a time constant of 1.8 dt / (k dt^2) = 2700 s: 67% of it by 3000 s.
    auto depth_after = [&](const Tuning& t, double duration) {
        Scenario run_for = s;
        run_for.duration = duration;
        return s.radius - probe(run_for, t).states.back().p.z();
    };
    auto expected = [&](const Tuning& t, double duration) {
        const double k_dt2 = t.damper_anchor * (1 - s.alpha);
        return 1e-4 * 0.0981 * s.dt * s.dt / k_dt2 * (1 - std::exp(-duration * k_dt2 / (1.8 * s.dt)));
    };
    const double deepest = 1e-4 * 0.0981 * s.dt * s.dt / (Tuning::chosen().damper_anchor * (1 - s.alpha));
    EXPECT_NEAR(depth_after(Tuning::chosen(), s.duration), expected(Tuning::chosen(), s.duration), 0.02 * deepest);
    // The equilibrium itself, with a 100x stronger anchor (27 s, 4.4 um): it stops there.
    Tuning strong = Tuning::chosen();
    strong.damper_anchor = 1e-2;
    EXPECT_NEAR(depth_after(strong, 400), expected(strong, 1e9), 0.01 * expected(strong, 1e9));
}

// MuJoCo 2.2 has no sleeping: a ball drifting at 0.1 mm/s in zero gravity
// keeps drifting for 100 s.
TEST(MujocoSettings, NoSleeping) {
    Scenario s = drop(0.2, 0.01, 100.0);
    s.gravity = Vec3::Zero();
    s.velocity = Vec3(1e-4, 0, 0);
    const Probe p = probe(s);
    EXPECT_NEAR(p.states.back().p.x(), 0.5 + 1e-4 * 100.0, 1e-11);
    EXPECT_EQ(setting(p.settings, "sleeping"), "none");
}

// The law is per unit mass: MuJoCo's default density (0.52 kg for r = 5 cm)
// and 1 kg give the same run, in both tangential models.
TEST(MujocoSettings, BallMassDoesNotChangeTheAnswer) {
    for (const bool per_contact : {true, false}) {
        Scenario s = variant(seed("seed-3d.toml"), 0.01, 20.0, per_contact);
        if (!per_contact) s.engines["mujoco"].friction = 0.05;
        Tuning density = Tuning::chosen();
        density.ball_mass = 0;
        const Probe a = probe(s), b = probe(s, density);
        EXPECT_NEAR(b.world->ball_mass(), 1000 * 4.0 / 3.0 * M_PI * std::pow(s.radius, 3), 1e-9);
        EXPECT_EQ(a.world->ball_mass(), 1.0);
        double worst = 0;
        for (std::size_t k = 0; k < a.states.size(); ++k)
            worst = std::max(worst, (a.states[k].p - b.states[k].p).norm());
        EXPECT_LT(worst, 1e-9) << "per_contact " << per_contact;
    }
}

// impratio scales the friction rows' regulariser only; the normal-friction
// coupling of the elliptic cone (MujocoWeakness) does not depend on it
// (mj_constraintUpdate's middle zone: jar_n = friction |jar_t| whatever mu's
// regularisation).
TEST(MujocoSettings, ImpratioChangesNothingHere) {
    const Scenario s = sliding_drop(2, 0.05, Vec3(0.1, 0, 0));
    Tuning ten = Tuning::chosen();
    ten.impratio = 10;
    const auto a = floor_bounces(s, probe(s).states), b = floor_bounces(s, probe(s, ten).states);
    ASSERT_EQ(a.size(), 1u);
    ASSERT_EQ(b.size(), 1u);
    // Measured: 8e-8 m/s apart (the friction rows' regulariser is 1e-4 of A).
    EXPECT_NEAR(a[0].after.v.x(), b[0].after.v.x(), 1e-6);
    EXPECT_NEAR(a[0].after.v.y(), b[0].after.v.y(), 1e-6);
}

TEST(MujocoSettings, EveryDeliberateSettingIsReported) {
    const Probe p = probe(variant(seed("seed-3d.toml"), 0.03, 0.03, true), Tuning::chosen(), 1);
    for (const char* key :
         {"engine", "precision", "unit_scale", "timestep", "integrator", "gravity", "axes", "contact.law",
          "contact.stiffness_rule", "contact.damping", "contact.solimp", "contact.margin_gap", "contact.condim",
          "contact.friction", "contact.cone", "contact.impratio", "contact.override", "solver", "walls", "ball",
          "joints", "rotation", "fluid", "sleeping", "ccd", "sizes", "warnings", "threads", "tangential_model"})
        EXPECT_EQ(setting(p.settings, key).rfind("<missing", 0), std::string::npos) << key;
    EXPECT_EQ(setting(p.settings, "engine").rfind("MuJoCo 2.2.2", 0), 0u);
    EXPECT_EQ(setting(p.settings, "timestep"), "0.029999999999999999 s (opt.timestep = dt)");
    // The compiled model carries what the settings say.
    const std::string& xml = p.world->model_xml();
    EXPECT_NE(xml.find("cone=\"elliptic\""), std::string::npos);
    EXPECT_NE(xml.find("integrator=\"Euler\""), std::string::npos);
    EXPECT_NE(xml.find("solimp=\"0.99990000000000001 0.99990000000000001"), std::string::npos);
}

// ---------------------------------------------------------------- the spring alternative

// The replayed step behind the spring law's damping: the continuous formula's
// b gives 0.807 (a contact that never pulls releases the ball early), the
// corrected b gives alpha on average, and the spread over the crossing phase
// shrinks with the steps per contact.
TEST(MujocoSpring, ReplayedRestitutionAndItsPhaseSpread) {
    const double alpha = 0.8, zeta = -std::log(alpha) / std::hypot(M_PI, std::log(alpha));
    const double omega_dt = M_PI / 40;
    EXPECT_NEAR(mujoco::spring_restitution(omega_dt, 2 * zeta * omega_dt).mean, 0.8077, 5e-4);
    Scenario s = drop(0.2, 1e-3, 1);
    Tuning spring = Tuning::chosen();
    spring.law = ContactLaw::spring;
    const auto c = mujoco::contact_parameters(s, spring);
    const auto r = mujoco::spring_restitution(c.omega_dt, c.damping * c.impedance_factor * s.dt);
    EXPECT_NEAR(r.mean, alpha, 1e-9);
    EXPECT_GT(c.damping, 1.03 * c.damping_derived);  // the correction is ~4%
    EXPECT_GT(r.highest - r.lowest, 0.02);            // +-2% with the rule's ~11 steps per contact
    EXPECT_GE(r.steps, 8);
}

// The spring law with the stiffness rule at dt 1e-3 (about 11 steps per
// contact, penetration under 4% of r): the phase spread moves the apexes by
// up to 6% of exact's (the damper: 0.1 mm). And the early probes' k = 1000:
// 10 mm deep, floor contacts 1% late.
TEST(MujocoSpring, StiffnessRuleAndTheEarlyProbe) {
    const Scenario s = variant(seed("seed-2d.toml"), 1e-3, 17.0, true);
    const ExactModel exact(s);
    Tuning spring = Tuning::chosen();
    spring.law = ContactLaw::spring;
    const Outcome rule = run(s, spring);
    ASSERT_EQ(rule.summary.status, RunStatus::ok);
    ASSERT_GE(rule.summary.apexes.size(), 3u);
    double worst = 0;
    for (int i = 1; i < 3; ++i)
        worst = std::max(worst, std::abs(rule.summary.apexes[i].height - exact.apexes()[i].height) /
                                    (exact.apexes()[i].height - s.radius));
    EXPECT_GT(worst, 0.03);
    EXPECT_LT(rule.summary.max_penetration, 0.04 * s.radius + 1e-4);

    Tuning probe_k = spring;
    probe_k.spring_stiffness = 1000;
    const Outcome early = run(s, probe_k);
    EXPECT_GT(early.summary.max_penetration, 0.009);
    const auto t = first_floor_event(early.summary, 1);
    ASSERT_TRUE(t.has_value());
    EXPECT_GT(*t, 1.008 * first_exact_floor_contact(exact, 1));
}

// ---------------------------------------------------------------- friction mode

// Coulomb friction as MuJoCo makes it: a sliding bounce loses mu times the
// normal impulse along the slip (2D, and a 3D diagonal).
TEST(MujocoFriction, SlidingBounceLosesMuTimesTheNormalImpulse) {
    for (const int dim : {2, 3}) {
        const Scenario s = sliding_drop(dim, 0.05, dim == 2 ? Vec3(0.1, 0, 0) : Vec3(0.1, 0.1, 0));
        const auto b = floor_bounces(s, probe(s).states);
        ASSERT_EQ(b.size(), 1u);
        const int z = dim - 1;
        const Vec3 dv = b[0].after.v - b[0].before.v;
        const double dt_norm = dim == 2 ? std::abs(dv.x()) : std::hypot(dv.x(), dv.y());
        EXPECT_NEAR(dt_norm / dv[z], 0.05, 1e-4) << dim;
    }
}

// A weakness of MuJoCo's soft elliptic cone (engine_core_constraint.c,
// mj_constraintUpdate, "middle zone"): while sliding, the solver puts the
// contact on the cone of constraint-space accelerations, jar_n = mu |jar_t|,
// so the normal row overshoots its reference by mu |jar_t|. With the damper
// (friction rows share aref = -b v) that is (1 + alpha) mu |v_slip| of extra
// normal speed per contact step: the bounce is too lively, and a ball
// sliding on the floor hops.
TEST(MujocoWeakness, SlidingFrictionAddsNormalSpeed) {
    const double mu = 0.05;
    const Scenario s = sliding_drop(2, mu, Vec3(0.1, 0, 0));
    const auto b = floor_bounces(s, probe(s).states);
    ASSERT_EQ(b.size(), 1u);
    // The friction row's jar is (v_out - v_in) / dt + b v_in = (v_out + alpha v_in) / dt
    // (locked rotation: the slip is the ball's sideways speed).
    const double u = -b[0].before.v.y();
    const double predicted = s.alpha * u + mu * (b[0].after.v.x() + s.alpha * b[0].before.v.x());
    EXPECT_NEAR(b[0].after.v.y(), predicted, 1e-4 * u);
    EXPECT_GT(b[0].restitution(1), s.alpha + 0.02);  // measured 0.826

    // Sliding along the floor at 0.1 m/s from rest on it: it leaves the floor.
    Scenario slide = drop(0, 1e-3, 1.0, 2);
    slide.position.y() = slide.radius - 1e-9;
    slide.velocity = Vec3(0.1, 0, 0);
    slide.engines["mujoco"].friction = mu;
    slide.engines["mujoco"].free_rotation = false;
    double highest = 0;
    for (const State& st : probe(slide).states) highest = std::max(highest, st.p.y() - slide.radius);
    EXPECT_GT(highest, 1e-3);
}

// Another: friction rows share the normal's aref = -b v, so within the cone a
// contact drives its slip to -alpha x slip instead of 0. mu = 1: a locked
// ball leaves with -0.8 of its sideways speed; a free one with
// 0.1 (1 - 2/7 x 1.8) = 0.0486 instead of rolling at 5/7 x 0.1 = 0.0714.
TEST(MujocoWeakness, StickingContactReversesItsSlip) {
    const Scenario locked = sliding_drop(3, 1.0, Vec3(0.1, 0, 0), false);
    const auto b = floor_bounces(locked, probe(locked).states);
    ASSERT_EQ(b.size(), 1u);
    EXPECT_NEAR(b[0].after.v.x(), -0.8 * 0.1, 1e-4);
    const Scenario free = sliding_drop(3, 1.0, Vec3(0.1, 0, 0), true);
    const auto f = floor_bounces(free, probe(free).states);
    ASSERT_EQ(f.size(), 1u);
    // Measured 0.04844: MuJoCo's contact point lies half the depth inside the
    // ball, which shortens the lever arm of the spin.
    EXPECT_NEAR(f[0].after.v.x(), 0.1 * (1 - 2.0 / 7.0 * 1.8), 5e-4);
}

// ---------------------------------------------------------------- threads

// Worlds build (mj_loadXML, serialised) and step on several threads at once
// and give, bit for bit, the states of a serial run.
TEST(MujocoThreads, ConcurrentWorldsMatchSerialRuns) {
    std::vector<Scenario> scenarios;
    for (const char* file : {"seed-2d.toml", "seed-3d.toml"})
        for (const bool per_contact : {false, true}) {
            Scenario s = variant(seed(file), 0.01, 15.0, per_contact);
            if (!per_contact) s.engines["mujoco"].friction = 0.02;
            scenarios.push_back(s);
        }
    std::vector<State> serial;
    for (const Scenario& s : scenarios) serial.push_back(probe(s).states.back());
    std::vector<std::vector<State>> parallel(4);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
            for (int repeat = 0; repeat < 3; ++repeat)
                for (const Scenario& s : scenarios) parallel[t].push_back(probe(s).states.back());
        });
    for (auto& th : threads) th.join();
    for (int t = 0; t < 4; ++t) {
        ASSERT_EQ(parallel[t].size(), 3 * scenarios.size());
        for (std::size_t i = 0; i < parallel[t].size(); ++i) {
            EXPECT_EQ(parallel[t][i].p, serial[i % scenarios.size()].p) << t << " " << i;
            EXPECT_EQ(parallel[t][i].v, serial[i % scenarios.size()].v) << t << " " << i;
        }
    }
}

// ---------------------------------------------------------------- command line

// `bouncecheck run` lists mujoco with its settings; `sweep` and `stress` run it.
TEST(MujocoCli, RunSweepAndStress) {
    const fs::path dir = fs::temp_directory_path() / ("bouncecheck-mujoco-cli-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::string toml = test::slurp(fs::path(BOUNCECHECK_SCENARIO_DIR) / "seed-2d-per-contact.toml");
    toml = toml.substr(0, toml.find("[engines.")) + "[engines.mujoco]\ntangential_model = \"per-contact\"\n";
    const fs::path file = dir / "mujoco-seed.toml";
    std::ofstream(file) << toml;

    const auto r = test::bouncecheck("run " + file.string() + " --engines reference,exact,mujoco --out " +
                                     (dir / "run").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const auto report = nlohmann::json::parse(test::slurp(dir / "run" / "report.json"));
    const auto& sims = report["scenarios"][0]["simulators"];
    ASSERT_EQ(sims.size(), 3u);
    EXPECT_EQ(sims[2]["simulator"], "mujoco");
    EXPECT_EQ(sims[2]["status"], "ok") << sims[2].dump();
    EXPECT_NE(sims[2].dump().find("contact.law"), std::string::npos);

    const auto sw = test::bouncecheck("sweep " + file.string() + " --engines mujoco --dt 0.03,0.015 --repeat 1 "
                                      "--jobs 2 --out " + (dir / "sweep").string());
    ASSERT_EQ(sw.status, 0) << sw.output;
    const std::string csv = test::slurp(dir / "sweep" / "sweep.csv");
    EXPECT_NE(csv.find("mujoco,0.029999999999999999,ok"), std::string::npos) << csv;
    EXPECT_NE(csv.find("mujoco,0.014999999999999999,ok"), std::string::npos) << csv;

    const auto st = test::bouncecheck("stress --engines mujoco --only wall-starts corner-2d corner-3d --jobs 2 --out " +
                                      (dir / "stress").string());
    EXPECT_EQ(st.status, 0) << st.output;
    fs::remove_all(dir);
}

}  // namespace
}  // namespace bouncecheck

namespace bouncecheck {
namespace {

// MuJoCo 2.2.2's own test python/mujoco/bindings_test.py (test_mj_step): a
// body 0.25 m above the floor plane falls under -9.81 with timestep 2^-9;
// the test asserts no contact (ncon == 0) while the time is below the free
// fall's sqrt(2 h / g), and contacts once past it. The adapter's sphere at
// the same height holds both: pure free fall (the semi-implicit Euler of
// MuJoCo's integrator, v_n = -g t_n) until then, and the bounce within two
// steps of it. MuJoCo 2.2.2 has no restitution test (its docs' solref < 0
// example has none behind it).
TEST(MujocoOwnTests, MjStepNoContactBeforeTheFreeFallTime) {
    const double g = 9.81, h = 0.25, r = 0.1, dt = 1.0 / 512;
    const double contact_time = std::sqrt(2 * h / g);
    const Scenario sc = test::make_scenario(3, Vec3(1, 1, 1), r, Vec3(0.5, 0.5, r + h), Vec3::Zero(),
                                            Vec3(0, 0, -g), 0.8, 1.0, 0.4, dt);
    const auto run = test::run_simulator("mujoco", sc);
    ASSERT_EQ(run.summary.status, RunStatus::ok) << run.summary.reason;
    std::optional<double> first_rise;
    double free_fall_error = 0;
    for (const State& st : run.states) {
        if (!first_rise && st.v.z() > 0) first_rise = st.t;
        if (st.t < contact_time - dt) free_fall_error = std::max(free_fall_error, std::abs(st.v.z() + g * st.t));
    }
    ASSERT_TRUE(first_rise);
    std::printf("free fall to %.6f s: velocity error %.3g m/s; first rise at %.6f s\n", contact_time,
                free_fall_error, *first_rise);
    EXPECT_LT(free_fall_error, 1e-9);
    EXPECT_GE(*first_rise, contact_time - dt);
    EXPECT_LE(*first_rise, contact_time + 2 * dt);
}

}  // namespace
}  // namespace bouncecheck
