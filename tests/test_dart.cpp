// The DART 6.12 adapter: against the exact model at a small step, inside the
// room, at the seed's step, friction mode, the per-contact hook, and one test
// per trap: DART's default restored through dartsim::Tuning and its physical
// consequence measured next to the adapter's choice.
#include "engines/dart/dart_adapter.h"
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
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <unistd.h>
#include <vector>

namespace bouncecheck {
namespace {

namespace fs = std::filesystem;
using dartsim::Detector;
using dartsim::Tuning;
using test::setting;
using test::first_exact_floor_contact;
using test::first_floor_event;

Scenario seed(const char* file) { return test::bundled_seed(file); }

Scenario variant(Scenario s, double dt, double duration, bool per_contact) {
    s.dt = dt;
    s.duration = duration;
    if (per_contact) s.engines["dart"].tangential_model = TangentialModel::per_contact;
    return s;
}

test::SimulatorRun run_dart(const Scenario& s, const Tuning& tuning = {}) {
    return test::record_states(*dartsim::make_simulator(tuning), s);
}

// The world stepped bare, one state per step, with its stats.
struct Probe {
    std::vector<State> states;
    std::vector<Setting> settings;
    dartsim::Stats stats;
    double spin_max = 0;
    double scale = 0;
};
Probe probe(const Scenario& s, const Tuning& tuning = {}, long steps = -1) {
    Probe out;
    const auto world = dartsim::build_world(s, s.engine_options("dart"), tuning, out.settings);
    out.scale = world->length_scale();
    State st{0, s.position, s.velocity};
    out.states.push_back(st);
    if (steps < 0) steps = std::llround(s.duration / s.dt);
    for (long k = 1; k <= steps; ++k) {
        world->step();
        world->read(st);
        st.t = static_cast<double>(k) * s.dt;
        out.states.push_back(st);
        out.spin_max = std::max(out.spin_max, world->spin());
    }
    out.stats = world->stats();
    return out;
}

// Largest relative error of the first n apex heights against exact's
// (relative to the height above the resting centre, as the brief's 3%).
double apex_error(const SimulatorSummary& r, const ExactModel& exact, double radius, std::size_t n) {
    double worst = 0;
    for (std::size_t i = 0; i < n && i < r.apexes.size() && i < exact.apexes().size(); ++i)
        worst = std::max(worst, std::abs(r.apexes[i].height - exact.apexes()[i].height) /
                                    (exact.apexes()[i].height - radius));
    return worst;
}

// Vertical speed range over the last `seconds` of a run (0 at rest).
double late_vertical_speed(const std::vector<State>& states, int z, double seconds) {
    const double t_end = states.back().t;
    double v = 0;
    for (const State& st : states)
        if (st.t >= t_end - seconds) v = std::max(v, std::abs(st.v[z]));
    return v;
}

// ---------------------------------------------------------------- capabilities

TEST(DartCapabilities, DoubleThreeAndTwoDimensionsSerial) {
    const auto sim = dartsim::make_simulator({});
    const auto* engine = dynamic_cast<const EngineSimulator*>(sim.get());
    ASSERT_NE(engine, nullptr);
    EXPECT_EQ(sim->name(), "dart");
    const EngineCapabilities caps = engine->capabilities();
    EXPECT_TRUE(caps.runs_3d);
    EXPECT_TRUE(caps.runs_2d);
    EXPECT_TRUE(caps.per_contact_hook);
    EXPECT_EQ(caps.precision, "double");
    EXPECT_NO_THROW(test::find_simulator("dart"));
}

// ---------------------------------------------------------------- exact

// The brief's acceptance: per-contact mode at dt = 1e-3 on both seeds.
TEST(DartExact, PerContactSeedsAtSmallStep) {
    for (const char* file : {"seed-3d-per-contact.toml", "seed-2d-per-contact.toml"}) {
        const Scenario s = variant(seed(file), 1e-3, 20.0, true);
        const ExactModel exact(s);
        const auto r = test::run_simulator("dart", s);
        ASSERT_EQ(r.summary.status, RunStatus::ok) << file << ": " << r.summary.reason;
        const int z = s.vertical_axis();

        const auto t_first = first_floor_event(r.summary, z);
        ASSERT_TRUE(t_first.has_value()) << file;
        const double t_exact = first_exact_floor_contact(exact, z);
        EXPECT_LT(std::abs(*t_first - t_exact) / t_exact, 0.01) << file;
        // Semi-implicit Euler finds the contact at the step's start: a step or two late.
        EXPECT_NEAR(*t_first, t_exact, 2.5 * s.dt) << file;

        ASSERT_GE(r.summary.apexes.size(), 3u) << file;
        EXPECT_LT(apex_error(r.summary, exact, s.radius, 3), 0.03) << file;
        // Measured: within 0.2% (seed-3d 0.0995 -> apexes -0.01% .. +0.1%).
        EXPECT_LT(apex_error(r.summary, exact, s.radius, 3), 0.005) << file;

        // One step of travel at most: 0.44 m/s x 1 ms.
        EXPECT_LE(r.summary.max_penetration, 2e-3) << file;
        EXPECT_LE(r.summary.max_penetration, 0.6e-3) << file;
        RecordProperty(std::string(file) + ".max_penetration", std::to_string(r.summary.max_penetration));
    }
}

// At the seed's own step: the ball bounces, rests, stays in the room. At
// dt 0.03 the rule picks a length scale of about 4.2 (threshold e |v_n| >
// 2.4 cm/s), so the ball settles.
TEST(DartSeeds, PerContactAtTheSeedStep) {
    for (const char* file : {"seed-3d-per-contact.toml", "seed-2d-per-contact.toml"}) {
        const Scenario s = variant(seed(file), 0.03, 45.0, true);
        const ExactModel exact(s);
        const auto r = run_dart(s);
        ASSERT_EQ(r.summary.status, RunStatus::ok) << file << ": " << r.summary.reason;
        EXPECT_GE(r.summary.apexes.size(), 8u) << file;
        // Measured: apexes 1-3 within 2.1% (2D) and 2.1% (3D) of exact.
        EXPECT_LT(apex_error(r.summary, exact, s.radius, 3), 0.05) << file;
        ASSERT_TRUE(r.summary.rest_time.has_value()) << file;
        EXPECT_NEAR(*r.summary.rest_time, *exact.rest_time(), 2.0) << file;
        // A step of travel at 0.44 m/s is 1.3 cm; the ball's surface stays within r/2.
        EXPECT_LE(r.summary.max_penetration, s.radius / 2) << file;
        // At rest: what is left is the error reduction's lift (at most its max
        // velocity, 1e-3 model units/s = 2.4e-4 m/s here), not a hop (1.2 cm/s).
        EXPECT_LT(late_vertical_speed(r.states, s.vertical_axis(), 2.0), 3e-4) << file;
    }
}

// The 2D run stays in its plane and reads back 2D states.
TEST(DartPlanar, TwoDimensionalRunStaysInItsPlane) {
    for (const bool free_rotation : {true, false}) {
        Scenario s = variant(seed("seed-2d.toml"), 0.01, 10.0, false);
        s.engines["dart"].friction = 0.05;
        s.engines["dart"].free_rotation = free_rotation;
        const Probe p = probe(s);
        for (const State& st : p.states) ASSERT_EQ(st.p.z(), 0.0);
        EXPECT_NE(setting(p.settings, "joints").find(free_rotation ? "PlanarJoint" : "TranslationalJoint2D"),
                  std::string::npos);
    }
}

// ---------------------------------------------------------------- per-contact hook

TEST(DartPerContact, ScalesTangentialVelocityOncePerContact) {
    Scenario s = variant(seed("seed-2d-per-contact.toml"), 1e-3, 20.0, true);
    const Probe p = probe(s);
    const auto hits = test::floor_hits(p.states, s.radius);
    ASSERT_GE(hits.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i)
        EXPECT_NEAR(hits[i].after.v.x() / hits[i].before.v.x(), s.beta, 1e-12) << "floor hit " << i;
    // The start against the ceiling (gravity pulls away) is no contact.
    EXPECT_GT(p.stats.new_wall_contacts, p.stats.beta_applied);
    EXPECT_GE(p.stats.beta_applied, 3);
    // An analytic sphere against a box: one contact per wall touched.
    EXPECT_LE(p.stats.max_contacts, 2u);
}

// After the step instead: the contact step still moves the ball with the
// unscaled velocity; the apexes barely move, the first contact's beta lands a step late.
TEST(DartPerContact, AfterTheStepScalesAStepLate) {
    Scenario s = variant(seed("seed-2d-per-contact.toml"), 1e-3, 8.0, true);
    Tuning late;
    late.beta_before_step = false;
    const Probe before = probe(s), after = probe(s, late);
    ASSERT_EQ(before.states.size(), after.states.size());
    double dx = 0;
    for (std::size_t i = 0; i < before.states.size(); ++i)
        dx = std::max(dx, std::abs(before.states[i].p.x() - after.states[i].p.x()));
    EXPECT_GT(dx, 0.0);
    EXPECT_LT(dx, 3e-5);  // (1 - beta) v_t dt per contact: 3e-6 m
}

// ---------------------------------------------------------------- friction

TEST(DartFriction, SlidingBounceLosesTangentialSpeed) {
    Scenario s = seed("seed-3d.toml");
    s.position = {0.5, 0.5, 0.5};
    s.velocity = {0.1, 0.05, 0};
    s.dt = 1e-3;
    s.duration = 3.2;  // one floor contact at ~3.03 s
    s.engines["dart"].friction = 0.05;
    const Probe p = probe(s);
    const Vec3 start = p.states.front().v, end = p.states.back().v;
    const double kept = std::hypot(end.x(), end.y()) / std::hypot(start.x(), start.y());
    EXPECT_LT(kept, 0.95);
    EXPECT_GT(kept, 0.0);
    // Coulomb acts against the slip: the direction is kept.
    EXPECT_NEAR(end.y() / end.x(), 0.5, 1e-9);
    // DART's fixed basis: x and y are each bounded by mu N, so the diagonal
    // slip (2:1) loses the same speed on both and turns towards 45 degrees.
    // Measured 0.4866.
    Tuning fixed_basis;
    fixed_basis.friction_along_slip = false;
    const Probe pyramid = probe(s, fixed_basis);
    const Vec3 turned = pyramid.states.back().v;
    EXPECT_LT(turned.y() / turned.x(), 0.5 - 0.005);
    EXPECT_GT(turned.y() / turned.x(), 0.45);
    RecordProperty("fixed_basis_ratio", std::to_string(turned.y() / turned.x()));
    // No friction at all below DART_FRICTION_COEFF_THRESHOLD 1e-3.
    s.engines["dart"].friction = 9e-4;
    const Probe off = probe(s);
    EXPECT_EQ(off.states.back().v.x(), s.velocity.x());
}

// ---------------------------------------------------------------- traps

// DART's default restitution is 0 and combines as a product.
TEST(DartTraps, DefaultWallRestitutionKillsTheBounce) {
    const Scenario s = variant(seed("seed-3d-per-contact.toml"), 1e-3, 20.0, true);
    Tuning dead;
    dead.wall_restitution = 0;
    const auto chosen = run_dart(s), dflt = run_dart(s, dead);
    ASSERT_GE(chosen.summary.apexes.size(), 2u);
    EXPECT_NEAR(chosen.summary.apexes[1].height, 0.4590, 0.002);
    // Default: the ball lands and stays (no second apex above 1 mm).
    double highest_rebound = 0;
    for (std::size_t i = 1; i < dflt.summary.apexes.size(); ++i)
        highest_rebound = std::max(highest_rebound, dflt.summary.apexes[i].height - s.radius);
    EXPECT_LT(highest_rebound, 1e-3);
    RecordProperty("restitution_0_highest_rebound", std::to_string(highest_rebound));
}

// Length scale 1 (DART has no units): restitution only above e |v_n| = 0.1 m/s.
TEST(DartTraps, MetreScaleStopsBouncesEarly) {
    const Scenario s = variant(seed("seed-3d-per-contact.toml"), 1e-3, 42.0, true);
    Tuning metres;
    metres.length_scale = 1;
    const auto chosen = run_dart(s), one = run_dart(s, metres);
    ASSERT_TRUE(one.summary.rest_time.has_value());
    ASSERT_TRUE(chosen.summary.rest_time.has_value());
    // Measured: 25.3 s at scale 1, 34.15 s chosen (exact 34.03).
    EXPECT_LT(*one.summary.rest_time, 28.0);
    EXPECT_NEAR(*chosen.summary.rest_time, 34.03, 0.5);
    EXPECT_LT(one.summary.floor_contacts, chosen.summary.floor_contacts);
    RecordProperty("rest_scale_1", std::to_string(*one.summary.rest_time));
    RecordProperty("floor_contacts_scale_1", std::to_string(one.summary.floor_contacts));
    RecordProperty("floor_contacts_chosen", std::to_string(chosen.summary.floor_contacts));
}

// At dt 0.03 the resting hop e |g| dt / (1 - e) = 1.2 cm/s: in centimetres
// (scale 100) it is 1.2 model units/s, above the 0.1 threshold: the ball hops
// forever. The rule's scale (~4.2) settles it.
TEST(DartTraps, CentimetresAtTheSeedStepNeverSettle) {
    const Scenario s = variant(seed("seed-3d-per-contact.toml"), 0.03, 60.0, true);
    Tuning cm;
    cm.length_scale = 100;
    const Probe chosen = probe(s), hundred = probe(s, cm);
    EXPECT_NEAR(chosen.scale, 0.1 / (2 * 4 * 0.0981 * 0.03), 1e-9);
    EXPECT_LT(late_vertical_speed(chosen.states, 2, 10.0), 3e-4);
    EXPECT_GT(late_vertical_speed(hundred.states, 2, 10.0), 5e-3);
    RecordProperty("late_hop_speed_scale_100", std::to_string(late_vertical_speed(hundred.states, 2, 10.0)));
    RecordProperty("late_speed_chosen", std::to_string(late_vertical_speed(chosen.states, 2, 10.0)));
}

// DART's default collision detector: FCL with the sphere as a mesh.
TEST(DartTraps, FclMeshSphereSpinsAndSinks) {
    const Scenario s = variant(seed("seed-3d-per-contact.toml"), 1e-3, 20.0, true);
    const ExactModel exact(s);
    Tuning mesh;
    mesh.detector = Detector::fcl_mesh;
    const auto chosen = run_dart(s), fcl = run_dart(s, mesh);
    const Probe spin_chosen = probe(s, {}), spin_mesh = probe(s, mesh);
    EXPECT_LT(spin_chosen.spin_max, 1e-12);
    EXPECT_GT(spin_mesh.spin_max, 0.1);
    EXPECT_GT(fcl.summary.max_penetration, 3 * chosen.summary.max_penetration);
    EXPECT_GT(apex_error(fcl.summary, exact, s.radius, 5), 0.1);
    EXPECT_LT(apex_error(chosen.summary, exact, s.radius, 5), 0.01);
    RecordProperty("mesh_spin", std::to_string(spin_mesh.spin_max));
    RecordProperty("mesh_penetration", std::to_string(fcl.summary.max_penetration));
    RecordProperty("mesh_apex_error_5", std::to_string(apex_error(fcl.summary, exact, s.radius, 5)));
}

// FCL with primitive shapes is analytic too: the same bounces.
TEST(DartTraps, FclPrimitiveMatchesDartDetector) {
    const Scenario s = variant(seed("seed-3d-per-contact.toml"), 1e-3, 20.0, true);
    const ExactModel exact(s);
    Tuning primitive;
    primitive.detector = Detector::fcl_primitive;
    const auto fcl = run_dart(s, primitive);
    EXPECT_LT(apex_error(fcl.summary, exact, s.radius, 5), 0.01);
}

// World::setTimeStep left alone: every step advances 1 ms of DART time.
TEST(DartTraps, DefaultTimestepSlowsTime) {
    // Friction mode with mu = 0: the start against the back wall leaves x alone.
    Scenario s = variant(seed("seed-3d-per-contact.toml"), 0.01, 20.0, false);
    Tuning t;
    t.set_timestep = false;
    const Probe chosen = probe(s), slow = probe(s, t);
    EXPECT_NE(setting(slow.settings, "timestep").find("0.001 s (DART default)"), std::string::npos);
    // 100 steps: 1 s of flight, or 0.1 s: a tenth of the travel along x (0.3 m/s).
    const double travel_chosen = chosen.states[100].p.x() - s.position.x();
    const double travel_slow = slow.states[100].p.x() - s.position.x();
    EXPECT_NEAR(travel_chosen, 0.3, 1e-9);
    EXPECT_NEAR(travel_slow / travel_chosen, 0.1, 1e-9);
}

// World gravity left alone: Earth's, along -z, 100x the seed's.
TEST(DartTraps, DefaultGravityIsEarths) {
    Scenario s = variant(seed("seed-2d-per-contact.toml"), 1e-3, 1.0, true);
    Tuning t;
    t.set_gravity = false;
    const Probe p = probe(s, t, 100);
    // 2D: gravity along z is outside the plane: the ball does not fall at all.
    EXPECT_EQ(p.states.back().v.y(), s.velocity.y());
    EXPECT_NE(setting(p.settings, "gravity").find("DART default"), std::string::npos);
}

// The Dantzig solver and PGS agree on one contact; the error reduction
// defaults are what the adapter sets (explicitly, every step).
TEST(DartSettings, PgsAgreesOnOneContact) {
    const Scenario s = variant(seed("seed-3d-per-contact.toml"), 1e-3, 20.0, true);
    Tuning pgs;
    pgs.lcp = dartsim::LcpSolver::pgs;
    const auto a = run_dart(s), b = run_dart(s, pgs);
    ASSERT_GE(a.summary.apexes.size(), 3u);
    ASSERT_GE(b.summary.apexes.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(a.summary.apexes[i].height, b.summary.apexes[i].height, 1e-6);
}

// ERP: position correction through the contact velocity. With ERP 0 a
// resting ball stays as deep as it landed; DART's 0.01 (kept) lifts it out
// at up to the max error reduction velocity. Checked through a world that
// starts 1 mm inside the floor at rest.
TEST(DartSettings, ErrorReductionLiftsASunkenBall) {
    Scenario s = seed("seed-3d.toml");
    s.position = {0.5, 0.5, s.radius - 1e-3};
    s.velocity = Vec3::Zero();
    s.dt = 1e-3;
    s.duration = 5.0;
    Tuning none;
    none.error_reduction = 0;
    const Probe kept = probe(s), off = probe(s, none);
    const double depth_kept = s.radius - kept.states.back().p.z();
    const double depth_off = s.radius - off.states.back().p.z();
    EXPECT_NEAR(depth_off, 1e-3, 2e-5);
    EXPECT_LT(depth_kept, depth_off);
    RecordProperty("depth_after_5s_erp_0.01", std::to_string(depth_kept));
}

// ContactConstraint's ERP & co. are process-wide statics: each world sets
// its own before every step, so two worlds of different tunings stepped in
// turn on one thread give their serial runs bit for bit (and two threads
// would not: hence one world at a time per worker process).
TEST(DartThreads, InterleavedWorldsKeepTheirOwnErrorReduction) {
    Scenario s = seed("seed-3d.toml");
    s.position = {0.5, 0.5, s.radius - 1e-3};
    s.velocity = Vec3::Zero();
    s.dt = 1e-3;
    Tuning none;
    none.error_reduction = 0;
    const long steps = 2000;
    const State serial_kept = probe(s, {}, steps).states.back();
    const State serial_off = probe(s, none, steps).states.back();
    ASSERT_NE(serial_kept.p.z(), serial_off.p.z());
    std::vector<Setting> settings;
    const auto kept = dartsim::build_world(s, s.engine_options("dart"), {}, settings);
    const auto off = dartsim::build_world(s, s.engine_options("dart"), none, settings);
    for (long k = 0; k < steps; ++k) {
        kept->step();
        off->step();
    }
    State a, b;
    kept->read(a);
    off->read(b);
    EXPECT_EQ(a.p, serial_kept.p);
    EXPECT_EQ(b.p, serial_off.p);
}

TEST(DartSettings, EveryDeliberateSettingIsReported) {
    Scenario s = variant(seed("seed-3d-per-contact.toml"), 0.03, 1.0, true);
    const auto r = run_dart(s);
    for (const char* key : {"engine", "precision", "length_scale", "timestep", "gravity", "joints",
                            "collision_detector", "restitution", "restitution_threshold", "friction", "friction_direction",
                            "contact.error_reduction", "lcp_solver", "max_contacts", "walls", "ball", "sleeping",
                            "ccd", "threads", "tangential_model", "substeps"})
        EXPECT_EQ(setting(r.summary, key).rfind("<missing", 0), std::string::npos) << key;
    EXPECT_EQ(setting(r.summary, "engine").substr(0, 10), "DART 6.12.");
}

// ---------------------------------------------------------------- command line

TEST(DartCli, RunSweepStressAndCalibrate) {
    const fs::path dir = fs::temp_directory_path() / ("bouncecheck-dart-cli-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::string toml = test::slurp(fs::path(BOUNCECHECK_SCENARIO_DIR) / "seed-2d-per-contact.toml");
    toml = toml.substr(0, toml.find("[engines.")) + "[engines.dart]\ntangential_model = \"per-contact\"\n";
    const fs::path file = dir / "dart-seed.toml";
    std::ofstream(file) << toml;

    const auto r = test::bouncecheck("run " + file.string() + " --engines reference,exact,dart --out " +
                                     (dir / "run").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const auto report = nlohmann::json::parse(test::slurp(dir / "run" / "report.json"));
    const auto& sims = report["scenarios"][0]["simulators"];
    ASSERT_EQ(sims.size(), 3u);
    EXPECT_EQ(sims[2]["simulator"], "dart");
    EXPECT_EQ(sims[2]["status"], "ok") << sims[2].dump();
    EXPECT_NE(sims[2].dump().find("length_scale"), std::string::npos);

    const auto sw = test::bouncecheck("sweep " + file.string() + " --engines dart --dt 0.03,0.015 --repeat 1 "
                                      "--jobs 2 --out " + (dir / "sweep").string());
    ASSERT_EQ(sw.status, 0) << sw.output;
    const std::string csv = test::slurp(dir / "sweep" / "sweep.csv");
    EXPECT_NE(csv.find("dart,0.029999999999999999,ok"), std::string::npos) << csv;
    EXPECT_NE(csv.find("dart,0.014999999999999999,ok"), std::string::npos) << csv;

    const auto st = test::bouncecheck("stress --engines dart --only wall-starts corner-2d corner-3d --jobs 2 --out " +
                                      (dir / "stress").string());
    EXPECT_EQ(st.status, 0) << st.output;

    const auto cal = test::bouncecheck("calibrate " + std::string(BOUNCECHECK_SCENARIO_DIR) +
                                       "/seed-2d.toml --engine dart");
    EXPECT_EQ(cal.status, 0) << cal.output;
    EXPECT_NE(cal.output.find("mu"), std::string::npos) << cal.output;
    fs::remove_all(dir);
}

}  // namespace
}  // namespace bouncecheck

namespace bouncecheck {
namespace {

// DART 6.12.1's own regression test unittests/regression/test_Issue1184.cpp
// (TEST(Issue1184, Accuracy)): a sphere of radius s dropped 1 m onto the
// ground under -9.81 at dt = 0.001, restitution 0 (DART's default) and
// friction 1, run until 30 times the strike time plus 0.5 s. It asserts the
// ball reached the ground (its lowest centre height <= s + 1e-3) and rests
// there (final centre height within 1e-3 of s), for s in {0.25, 1, 5, 10, 20}
// (Release builds).
//
// At DART's own unit (length scale 1) the adapter holds both for every size.
// At the adapter's length scale (4.4 here, set so that the seeds' slow bounces
// clear DART's 0.1 model-units/s restitution threshold) the 0.25 m ball rests
// 1.26 mm deep: DART corrects penetration at most DART_MAX_ERV = 1e-3 model
// units/s, which is 1e-3 / scale m/s, so the 4.3 mm of the first impact takes
// longer to push out. A finding, held here: the scale that lets the seeds
// bounce slows DART's penetration recovery by the same factor.
struct Issue1184Result {
    double lowest = 0, final_height = 0;
};
Issue1184Result issue_1184_drop(double radius, const Tuning& tuning) {
    const double g = 9.81, drop = 1.0;
    const double strike = std::sqrt(2.0 * drop / g);
    const double side = 2 * radius + 10;
    Scenario sc = test::make_scenario(3, Vec3(side, side, drop + 2 * radius + 5), radius,
                                      Vec3(side / 2, side / 2, drop + radius), Vec3::Zero(), Vec3(0, 0, -g), 0.0, 1.0,
                                      30 * strike + 0.5, 0.001);
    sc.engines["dart"].friction = 1.0;  // DART's default friction coefficient
    const auto r = run_dart(sc, tuning);
    EXPECT_EQ(r.summary.status, RunStatus::ok) << r.summary.reason;
    Issue1184Result out{std::numeric_limits<double>::infinity(), r.states.back().p.z()};
    for (const State& st : r.states) out.lowest = std::min(out.lowest, st.p.z());
    std::printf("radius %g, length scale %s: lowest centre %.6g m, final %.6g m (t = %.3f s)\n", radius,
                test::setting(r.summary, "length_scale").c_str(), out.lowest, out.final_height, r.states.back().t);
    return out;
}

TEST(DartOwnTests, Issue1184SphereDropRestsOnTheGroundAtDartsOwnUnit) {
    const double tolerance = 1e-3;  // the test's own
    Tuning dart_unit;
    dart_unit.length_scale = 1.0;
    for (const double radius : {0.25, 1.0, 5.0, 10.0, 20.0}) {
        const Issue1184Result r = issue_1184_drop(radius, dart_unit);
        EXPECT_GE(radius + tolerance, r.lowest) << "radius " << radius;
        EXPECT_NEAR(radius, r.final_height, tolerance) << "radius " << radius;
    }
}

TEST(DartOwnTests, Issue1184AtTheAdaptersLengthScaleTheSmallBallRestsDeeper) {
    const double radius = 0.25;
    Tuning dart_unit;
    dart_unit.length_scale = 1.0;
    const Issue1184Result at_unit = issue_1184_drop(radius, dart_unit);
    const Issue1184Result at_rule = issue_1184_drop(radius, Tuning{});
    EXPECT_GT(radius - at_rule.final_height, 1e-3);  // beyond the test's tolerance
    EXPECT_GT(radius - at_rule.final_height, 2 * (radius - at_unit.final_height));
}

}  // namespace
}  // namespace bouncecheck
