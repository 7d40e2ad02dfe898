// Bullet 3.24 (double) adapter: against the exact model, containment, the
// seeds, the planar 2D mapping, the per-contact hook, and one test per trap:
// each restores Bullet's default through bullet::Tuning and measures what it
// does to the ball, next to the chosen setting doing the right thing.
#include "engines/bullet/bullet_adapter.h"
#include "exact/exact_model.h"
#include "scenarios/loader.h"
#include "tests/support/engine_run.h"
#include "tests/support/engine_tests.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace bouncecheck {
namespace {

using bullet::Stepping;
using bullet::Tuning;
using test::setting;

Scenario seed(const std::string& file) { return test::bundled_seed(file); }

// The seed with another dt and duration; per_contact selects the document's
// tangential semantics (beta at each contact) instead of friction.
Scenario variant(Scenario s, double dt, double duration, bool per_contact) {
    s.dt = dt;
    s.duration = duration;
    if (per_contact) {
        EngineOptions o;
        o.tangential_model = TangentialModel::per_contact;
        s.engines["bullet"] = o;
    }
    return s;
}

// A ball at rest `height` above its floor-touching height, seed gravity.
Scenario drop(double height, double dt, double duration) {
    Scenario s;  // seed-3d's room, ball and damping
    s.name = "drop";
    s.position = Vec3(0.5, 0.5, s.radius + height);
    s.velocity = Vec3::Zero();
    return variant(s, dt, duration, true);
}

// Steps the world directly (the same world run() builds), one state per step.
struct Probe {
    std::vector<State> states;
    std::vector<Setting> settings;
    bullet::Stats stats;
    bool active_at_end = true;
    double max_abs_engine_y = 0, max_abs_engine_vy = 0;  // the 2D run's locked axis
};

Probe probe(const Scenario& s, const Tuning& tuning = Tuning::chosen()) {
    Probe out;
    const auto world = bullet::build_world(s, s.engine_options("bullet"), tuning, out.settings);
    State st{0, s.position, s.velocity};
    out.states.push_back(st);
    const auto steps = static_cast<long>(std::llround(s.duration / s.dt));
    for (long k = 1; k <= steps; ++k) {
        world->step();
        world->read(st);
        st.t = static_cast<double>(k) * s.dt;
        out.states.push_back(st);
        out.max_abs_engine_y = std::max(out.max_abs_engine_y, std::abs(world->engine_position().y()));
        out.max_abs_engine_vy = std::max(out.max_abs_engine_vy, std::abs(world->engine_velocity().y()));
    }
    out.stats = world->stats();
    out.active_at_end = world->ball_active();
    return out;
}

// Floor bounces seen in a state stream: the vertical velocity turns from down
// to not down near the floor. t is the state before the bounce step (the
// bounce happens in the step that starts there), restitution is outgoing over
// incoming normal speed between the two samples.
struct Bounce {
    double t;
    double restitution;
};

std::vector<Bounce> floor_bounces(const Scenario& s, const std::vector<State>& states) {
    const int z = s.vertical_axis();
    std::vector<Bounce> out;
    for (std::size_t k = 1; k < states.size(); ++k)
        // Near the floor as StreamContactDetector has it: one step of travel
        // at the incoming speed plus a tenth of the radius.
        if (states[k - 1].v[z] < 0 && states[k].v[z] >= 0 &&
            states[k].p[z] - s.radius <= -states[k - 1].v[z] * s.dt + 0.1 * s.radius)
            out.push_back({states[k - 1].t, -states[k].v[z] / states[k - 1].v[z]});
    return out;
}

double first_floor_contact_time(const ExactModel& m, int z) {
    for (const WallContact& c : m.contacts())
        if (c.axis == z && c.side < 0) return c.t;
    return -1;
}

// ---------------------------------------------------------------- exact

// seed-3d at dt = 1e-3 with the per-contact hook (the document's semantics),
// through the real run() path, against the exact solution.
TEST(BulletExact, SeedThreeDimensionalAtSmallStep) {
    const Scenario s = variant(seed("seed-3d.toml"), 1e-3, 16.5, true);
    const ExactModel exact(s);
    const auto run = test::run_simulator("bullet", s);
    ASSERT_EQ(run.summary.status, RunStatus::ok) << run.summary.reason;
    const auto bounces = floor_bounces(s, run.states);
    ASSERT_GE(bounces.size(), 3u);

    // First floor contact: Bullet finds it at the start of the first step that
    // begins inside the floor, so up to one step late; the pre-contact flight's
    // integration error (semi-implicit Euler, ~v dt / 2 = 0.18 mm of height at
    // 0.36 m/s) moves it by another ~0.5 ms. Two steps cover both.
    const double t_exact = first_floor_contact_time(exact, 2);
    EXPECT_NEAR(bounces[0].t, t_exact, 2 * s.dt);

    // Restitution: Bullet's target is alpha times the normal speed at the start
    // of the step (the sample before the bounce), and the solved velocity is the
    // next sample: alpha to round-off.
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(bounces[i].restitution, s.alpha, 1e-9) << "bounce " << i;

    // Apexes: each bounce and flight adds O(u dt) of height error (the bounce
    // is up to one step late, position u dt = 0.36 mm; semi-implicit Euler's
    // apex is off by v dt / 2). Three such terms per apex: 1 mm. Measured:
    // 1e-4, 0, 1.5e-4 m.
    ASSERT_GE(run.summary.apexes.size(), 3u);
    ASSERT_GE(exact.apexes().size(), 3u);
    for (std::size_t i = 0; i < 3; ++i)
        EXPECT_NEAR(run.summary.apexes[i].height, exact.apexes()[i].height, 1e-3) << "apex " << i;
}

// The same in 2D (the planar mapping), one apex after the first floor bounce.
TEST(BulletExact, SeedTwoDimensionalAtSmallStep) {
    const Scenario s = variant(seed("seed-2d.toml"), 1e-3, 12, true);
    const ExactModel exact(s);
    const auto run = test::run_simulator("bullet", s);
    ASSERT_EQ(run.summary.status, RunStatus::ok) << run.summary.reason;
    const auto bounces = floor_bounces(s, run.states);
    ASSERT_GE(bounces.size(), 1u);
    EXPECT_NEAR(bounces[0].t, first_floor_contact_time(exact, 1), 2 * s.dt);
    EXPECT_NEAR(bounces[0].restitution, s.alpha, 1e-9);
    ASSERT_GE(run.summary.apexes.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i)
        EXPECT_NEAR(run.summary.apexes[i].height, exact.apexes()[i].height, 1e-3) << "apex " << i;
}

// ---------------------------------------------------------------- room and seeds

// Both seeds at their dt, both tangential models: the ball stays inside the
// room. Bullet only finds a contact once the ball is inside the wall, so the
// centre may pass r by one step of travel (|v| dt, < 1.4 cm here) before the
// push-out (erp2 = 1) removes it in that step.
TEST(BulletRoom, BallNeverLeavesTheRoom) {
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        for (const bool per_contact : {false, true}) {
            const Scenario base = seed(file);
            const Scenario s = variant(base, base.dt, base.duration, per_contact);
            const auto run = test::run_simulator("bullet", s);
            ASSERT_EQ(run.summary.status, RunStatus::ok) << file << ": " << run.summary.reason;
            double max_speed = 0;
            for (const State& st : run.states) max_speed = std::max(max_speed, st.v.norm());
            const double tol = max_speed * s.dt;
            for (const State& st : run.states)
                for (int i = 0; i < s.dim; ++i) {
                    ASSERT_GE(st.p[i], s.radius - tol) << file << " axis " << i << " t " << st.t;
                    ASSERT_LE(st.p[i], s.room[i] - s.radius + tol) << file << " axis " << i << " t " << st.t;
                }
        }
    }
}

// The seed files as they are (friction model, mu = 0), at dt = 0.03.
TEST(BulletSeeds, RunAndBounceAtTheSeedStep) {
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        const Scenario s = seed(file);
        const auto run = test::run_simulator("bullet", s);
        EXPECT_EQ(run.summary.status, RunStatus::ok) << file << ": " << run.summary.reason;
        EXPECT_GE(run.summary.floor_contacts, 10) << file;
        ASSERT_GE(run.summary.apexes.size(), 4u) << file;
        for (std::size_t i = 1; i < 4; ++i)
            EXPECT_LT(run.summary.apexes[i].height, run.summary.apexes[i - 1].height) << file << " apex " << i;
        EXPECT_EQ(setting(run.summary, "precision").rfind("double", 0), 0u);
    }
}

// 2D runs in the engine's x-z plane: y never moves, even with friction and
// free rotation spinning the ball about the plane's normal.
TEST(BulletPlanar, TwoDimensionalRunStaysInItsPlane) {
    Scenario s = seed("seed-2d.toml");
    EngineOptions o;
    o.friction = 0.3;
    s.engines["bullet"] = o;
    const Probe p = probe(s);
    EXPECT_EQ(p.max_abs_engine_y, 0.0);
    EXPECT_EQ(p.max_abs_engine_vy, 0.0);
    EXPECT_GE(floor_bounces(s, p.states).size(), 5u);
    const auto sim = bullet::make_simulator(Tuning::chosen());
    const auto* engine = dynamic_cast<const EngineSimulator*>(sim.get());
    ASSERT_NE(engine, nullptr);
    EXPECT_TRUE(engine->capabilities().planar_2d_in_3d);
}

// ---------------------------------------------------------------- per-contact hook

// seed-3d starts touching the back wall, moving into it: the first step
// bounces it and scales the other components by beta once.
TEST(BulletPerContact, ScalesTangentialVelocityAtTheContactStep) {
    const Scenario s = variant(seed("seed-3d.toml"), 1e-3, 1e-3, true);
    const Probe p = probe(s);
    ASSERT_EQ(p.states.size(), 2u);
    const State& after = p.states[1];
    EXPECT_NEAR(after.v.x(), 0.3 * s.beta, 1e-15);
    EXPECT_NEAR(after.v.y(), -0.1 * s.alpha, 1e-15);
    EXPECT_NEAR(after.v.z(), 0.2 * s.beta + s.gravity.z() * s.dt, 1e-15);
    EXPECT_EQ(p.stats.new_wall_contacts, 1);
}

// seed-2d starts with the ball at rest against the ceiling, gravity pulling
// it away: not a contact for the law. Bullet reports that touch at distance
// 0; scaling the tangential velocity there by beta gave a dt-independent
// error (0.022 m RMS against exact at every dt of a seed-2d-per-contact
// sweep, observed order 0.04; 0.93 with this condition).
TEST(BulletPerContact, StartingAtRestAgainstTheCeilingIsNotAContact) {
    const Scenario s = variant(seed("seed-2d.toml"), 0.03, 0.3, true);
    const Probe p = probe(s);
    EXPECT_EQ(p.states.back().v.x(), 0.3);
    EXPECT_EQ(p.stats.new_wall_contacts, 1);  // Bullet saw the touch; the hook left it alone
}

// A lasting contact (alpha = 0: the ball slides on the floor, pressed by
// gravity) is one contact: beta once, not once per step.
TEST(BulletPerContact, LastingContactScalesOnce) {
    Scenario s = drop(0, 0.01, 1.0);
    s.alpha = 0;
    s.velocity = Vec3(0.3, 0, 0);
    const Probe p = probe(s);
    EXPECT_EQ(p.stats.new_wall_contacts, 1);
    EXPECT_GE(p.stats.touching_steps, 99);
    EXPECT_NEAR(p.states.back().v.x(), 0.3 * s.beta, 1e-15);
    EXPECT_NEAR(p.states.back().p.z(), s.radius, 1e-12);
}

// ---------------------------------------------------------------- traps

// Restitution (and friction) combine as the product of the two bodies'. Walls
// left at Bullet's default restitution 0 give no bounce whatever the ball's.
TEST(BulletTraps, CombinedRestitutionIsTheProduct) {
    const Scenario s = drop(0.1, 0.01, 4);
    Tuning naive = Tuning::chosen();
    naive.unit_wall_materials = false;
    const auto bad = floor_bounces(s, probe(s, naive).states);
    ASSERT_FALSE(bad.empty());
    EXPECT_NEAR(bad[0].restitution, 0.0, 1e-9);  // round-off of a cancelled velocity
    const Probe good = probe(s);
    const auto ok = floor_bounces(s, good.states);
    ASSERT_GE(ok.size(), 2u);
    EXPECT_NEAR(ok[0].restitution, s.alpha, 1e-9);
    auto value = [&](const std::string& key) {
        for (const auto& st : good.settings)
            if (st.key == key) return st.value;
        return std::string();
    };
    EXPECT_EQ(value("wall.restitution"), "1");
    EXPECT_EQ(value("wall.friction"), "1");
    EXPECT_EQ(value("ball.restitution"), "0.80000000000000004");
}

// m_restitutionVelocityThreshold (0.2 m/s): below it Bullet gives restitution
// 0. A 0.15 m/s impact (a 11.5 cm drop at 0.0981 m/s^2) must bounce; and
// seed-3d's ball, moving into the back wall at 0.1 m/s, must leave it.
TEST(BulletTraps, RestitutionVelocityThreshold) {
    const Scenario s = drop(0.115, 0.01, 3);
    Tuning dflt = Tuning::chosen();
    dflt.restitution_velocity_threshold = 0.2;
    const auto bad = floor_bounces(s, probe(s, dflt).states);
    ASSERT_FALSE(bad.empty());
    EXPECT_NEAR(bad[0].restitution, 0.0, 1e-9);  // round-off of a cancelled velocity
    const auto ok = floor_bounces(s, probe(s).states);
    ASSERT_FALSE(ok.empty());
    EXPECT_NEAR(ok[0].restitution, s.alpha, 1e-9);

    const Scenario s3 = variant(seed("seed-3d.toml"), 0.03, 1.5, true);
    EXPECT_EQ(probe(s3, dflt).states.back().p.y(), 0.95);  // stuck on the back wall
    EXPECT_LT(probe(s3).states.back().p.y(), 0.95 - 0.1);  // 0.08 m/s for 1.5 s

    const auto run = test::run_simulator("bullet", drop(0.115, 0.01, 0.01));
    EXPECT_EQ(setting(run.summary, "solver.restitution_velocity_threshold"), "0");
}

// Deactivation: a ball slower than 0.8 m/s for 2 s is put to sleep, frozen in
// mid-air. The chosen DISABLE_DEACTIVATION keeps it falling.
TEST(BulletTraps, DeactivationFreezesTheBallMidAir) {
    const Scenario s = variant(seed("seed-3d.toml"), 0.03, 3, true);
    Tuning dflt = Tuning::chosen();
    dflt.disable_deactivation = false;
    const Probe bad = probe(s, dflt);
    EXPECT_FALSE(bad.active_at_end);
    const State& end = bad.states.back();
    const State& at_2_5 = bad.states[static_cast<std::size_t>(std::llround(2.5 / s.dt))];
    EXPECT_EQ(end.p, at_2_5.p);  // not moving
    EXPECT_GT(end.p.z(), 0.5);   // in mid-air
    const Probe good = probe(s);
    EXPECT_TRUE(good.active_at_end);
    const ExactModel exact(s);
    EXPECT_NEAR(good.states.back().p.z(), exact.state_at(3).p.z(), 0.01);
}

// stepSimulation(dt) with the default arguments steps a fixed 1/60 s at most
// once per call: at dt = 0.03 the ball runs at 0.56x speed.
TEST(BulletTraps, DefaultStepSimulationArgumentsLoseTime) {
    const Scenario s = variant(seed("seed-3d.toml"), 0.03, 12, true);
    const double t_exact = first_floor_contact_time(ExactModel(s), 2);
    Tuning dflt = Tuning::chosen();
    dflt.stepping = Stepping::default_args;
    const auto bad = floor_bounces(s, probe(s, dflt).states);
    ASSERT_FALSE(bad.empty());
    EXPECT_GT(bad[0].t, 1.5 * t_exact);
    const auto ok = floor_bounces(s, probe(s).states);
    ASSERT_FALSE(ok.empty());
    EXPECT_NEAR(ok[0].t, t_exact, 2 * s.dt);
}

// Split impulse only below -0.04 m (Bullet's threshold): every shallower
// penetration is corrected by Baumgarte velocity, which adds energy. Every
// penetration split (chosen): restitution is alpha at every bounce.
TEST(BulletTraps, BaumgarteOnShallowPenetrationsAddsEnergy) {
    const Scenario s = variant(seed("seed-3d.toml"), 0.03, 25, true);
    Tuning dflt = Tuning::chosen();
    dflt.split_impulse_penetration_threshold = -0.04;
    dflt.erp2 = 0.2;  // Bullet's default as well
    const auto bad = floor_bounces(s, probe(s, dflt).states);
    ASSERT_GE(bad.size(), 3u);
    double worst = 0;
    for (std::size_t i = 0; i < 3; ++i) worst = std::max(worst, std::abs(bad[i].restitution - s.alpha));
    EXPECT_GT(worst, 0.05);  // measured 0.83, 0.84, 0.91
    const auto ok = floor_bounces(s, probe(s).states);
    ASSERT_GE(ok.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(ok[i].restitution, s.alpha, 1e-9) << "bounce " << i;
}

// The contact-breaking threshold makes a contact of a ball still short of the
// wall; the solver bounces it there with alpha u - gap / dt. At dt = 1e-3
// Bullet's 1.73 mm eats most of the bounce.
TEST(BulletTraps, ContactBreakingThresholdEatsTheBounceAtSmallStep) {
    const Scenario s = drop(0.2, 1e-3, 2.2);
    Tuning dflt = Tuning::chosen();
    dflt.contact_breaking_threshold = -1;  // Bullet's own
    const auto bad = floor_bounces(s, probe(s, dflt).states);
    ASSERT_FALSE(bad.empty());
    EXPECT_LT(bad[0].restitution, 0.7);
    const auto ok = floor_bounces(s, probe(s).states);
    ASSERT_FALSE(ok.empty());
    EXPECT_NEAR(ok[0].restitution, s.alpha, 1e-9);
}

// The world's default gravity is (0, -10, 0); the ball copies the world's
// gravity when added, so it must be set first.
TEST(BulletTraps, WorldGravityIsTheScenarios) {
    const Scenario s = drop(0.2, 0.01, 2.2);
    const auto world = [&](const Tuning& t) {
        std::vector<Setting> settings;
        return bullet::build_world(s, s.engine_options("bullet"), t, settings);
    };
    Tuning dflt = Tuning::chosen();
    dflt.set_gravity = false;
    EXPECT_EQ(world(dflt)->engine_gravity(), Vec3(0, -10, 0));
    EXPECT_EQ(world(Tuning::chosen())->engine_gravity(), s.gravity);
    // Free fall of 0.2 m at 0.0981 m/s^2 takes 2.02 s.
    const auto ok = floor_bounces(s, probe(s).states);
    ASSERT_FALSE(ok.empty());
    EXPECT_NEAR(ok[0].t, std::sqrt(2 * 0.2 / 0.0981), 2 * s.dt);
    EXPECT_TRUE(floor_bounces(s, probe(s, dflt).states).empty());
}

// Settings that are not traps at this scale but still change the answer are
// reported as used.
TEST(BulletSettings, EveryDeliberateSettingIsReported) {
    const auto run = test::run_simulator("bullet", drop(0.1, 0.01, 0.01));
    for (const char* key :
         {"engine", "precision", "unit_scale", "gravity", "solver.restitution_velocity_threshold",
          "solver.split_impulse", "solver.split_impulse_penetration_threshold", "solver.erp2", "solver.iterations",
          "solver.warm_starting", "walls", "wall.restitution", "wall.friction", "ball.shape", "ball.restitution",
          "ball.friction", "ball.damping", "ccd", "sleeping", "contact_breaking_threshold", "stepping",
          "tangential_model"})
        EXPECT_EQ(setting(run.summary, key).rfind("<missing", 0), std::string::npos) << key;
    EXPECT_EQ(setting(run.summary, "sleeping"), "off (DISABLE_DEACTIVATION)");
    EXPECT_EQ(setting(run.summary, "solver.split_impulse_penetration_threshold"), "1e+30");
    EXPECT_EQ(setting(run.summary, "contact_breaking_threshold").rfind("1.0000000000000001e-09 m", 0), 0u);
}

}  // namespace
}  // namespace bouncecheck
