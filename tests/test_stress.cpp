// The stress suite: the invariant checks against deliberately broken
// simulators, the Monte-Carlo generator, the bundled stress files and the
// ccd / substeps options they use, and `bouncecheck stress` end to end.
#include "commands/stress/stress_pipeline.h"
#include "commands/stress/stress_suite.h"
#include "scenarios/loader.h"
#include "scenarios/scenario_toml.h"
#include "simulators/simulator.h"
#include "tests/support/cli.h"
#include "tests/support/engine_run.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <iterator>
#include <vector>
#include <sstream>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <sys/resource.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace bouncecheck;

namespace {

const fs::path kStressDir = fs::path(BOUNCECHECK_SCENARIO_DIR) / "stress";

// A 2D ball flying right without gravity, 1 m room: x = 0.3 + 0.2 t.
Scenario flight() {
    Scenario s;
    s.name = "flight";
    s.dim = 2;
    s.room = Vec3(1, 1, 0);
    s.radius = 0.05;
    s.position = Vec3(0.3, 0.5, 0);
    s.velocity = Vec3(0.2, 0, 0);
    s.gravity = Vec3::Zero();
    s.dt = 0.01;
    s.duration = 1.0;
    return s;
}

// A test double: streams the states `state(n, s)` for n = 0, 1, ... through
// the real recorder, as the stepped simulators do, calling `cost(n)` per step.
class ScriptedSimulator final : public Simulator {
public:
    using StateFn = std::function<State(std::int64_t, const Scenario&)>;
    explicit ScriptedSimulator(StateFn state, std::function<void(std::int64_t)> cost = {})
        : state_(std::move(state)), cost_(std::move(cost)) {}
    std::string_view name() const override { return "scripted"; }
    std::string_view description() const override { return "test double"; }
    RunOutcome run(const Scenario& s, RunSink& sink) const override {
        RunOutcome out;
        const auto steps = static_cast<std::int64_t>(std::llround(s.duration / s.dt));
        out.run_seconds = timed_seconds([&] {
            for (std::int64_t n = 0; n <= steps; ++n) {
                if (cost_) cost_(n);
                if (!sink.on_state(state_(n, s), ContactMask{})) return;
            }
        });
        return out;
    }

private:
    StateFn state_;
    std::function<void(std::int64_t)> cost_;
};

// Free flight at the scenario's velocity (sound as long as no wall is reached).
State free_flight(std::int64_t n, const Scenario& s) {
    const double t = static_cast<double>(n) * s.dt;
    return State{t, s.position + s.velocity * t, s.velocity};
}

const InvariantCheck& check(const StressResult& r, Invariant i) {
    for (const InvariantCheck& c : r.checks)
        if (c.invariant == i) return c;
    throw std::runtime_error("no such check");
}

StressResult run_double(const Scenario& s, const Simulator& sim, double budget = kDefaultBudgetSeconds) {
    return run_stress_case(StressCase{"double", s, false}, sim, budget);
}

void spin_for(std::chrono::nanoseconds d) {
    const auto end = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < end) {
    }
}

// --- invariants against broken simulators ---

TEST(StressInvariants, SoundFlightPasses) {
    const ScriptedSimulator sound(free_flight);
    const StressResult r = run_double(flight(), sound);
    EXPECT_EQ(r.outcome, StressOutcome::pass) << r.reason;
    ASSERT_EQ(r.checks.size(), std::size(kInvariants));
    for (const InvariantCheck& c : r.checks) EXPECT_TRUE(c.held) << to_string(c.invariant);
    EXPECT_EQ(r.steps, 100);
}

TEST(StressInvariants, BallThroughAWallIsCaughtWhereItFirstSinksTooDeep) {
    Scenario s = flight();
    s.velocity = Vec3(1.0, 0, 0);  // reaches x = 0.95 (touching) at t = 0.65 and never turns
    const ScriptedSimulator leaky(free_flight);
    const StressResult r = run_double(s, leaky);
    EXPECT_EQ(r.outcome, StressOutcome::fail);
    const InvariantCheck& room = check(r, Invariant::in_room);
    EXPECT_FALSE(room.held);
    EXPECT_DOUBLE_EQ(room.tolerance, 0.025);
    // Penetration 0.3 + t - 0.95 exceeds r/2 first at the sample t = 0.68 (0.03 m).
    ASSERT_TRUE(room.first_t);
    EXPECT_NEAR(*room.first_t, 0.68, 1e-12);
    EXPECT_NEAR(room.first_value, 0.03, 1e-12);
    // The recorder stops the run once the centre is beyond the wall (x > 1,
    // t = 0.70 or 0.71 by rounding): the worst value is its max_penetration.
    EXPECT_GE(room.worst, 0.05 - 1e-12);
    EXPECT_LE(room.worst, 0.06 + 1e-12);
    EXPECT_EQ(r.first_broken()->invariant, Invariant::in_room);
}

TEST(StressInvariants, EnergyGainIsCaught) {
    // Speed grows 1% per step in the middle of the room: energy from nowhere.
    const ScriptedSimulator pumping([](std::int64_t n, const Scenario& s) {
        State st = free_flight(0, s);
        st.t = static_cast<double>(n) * s.dt;
        st.v *= std::pow(1.01, static_cast<double>(n));
        return st;
    });
    const Scenario s = flight();
    const StressResult r = run_double(s, pumping);
    EXPECT_EQ(r.outcome, StressOutcome::fail);
    const InvariantCheck& energy = check(r, Invariant::energy);
    EXPECT_FALSE(energy.held);
    // Tolerance: 1% of the starting kinetic energy 0.02 J/kg (no gravity).
    EXPECT_NEAR(energy.tolerance, 0.01 * 0.02, 1e-7);
    // 0.02 (1.01^(2n) - 1) > 2e-4 from n = 1 on (0.000402).
    ASSERT_TRUE(energy.first_t);
    EXPECT_NEAR(*energy.first_t, 0.01, 1e-12);
    EXPECT_NEAR(energy.worst, 0.02 * (std::pow(1.01, 200) - 1), 1e-9);
    EXPECT_TRUE(check(r, Invariant::in_room).held);
}

TEST(StressInvariants, NonFiniteStateIsCaught) {
    const ScriptedSimulator blowing_up([](std::int64_t n, const Scenario& s) {
        State st = free_flight(n, s);
        if (n >= 10) st.v.x() = std::numeric_limits<double>::quiet_NaN();
        return st;
    });
    const StressResult r = run_double(flight(), blowing_up);
    EXPECT_EQ(r.outcome, StressOutcome::fail);
    const InvariantCheck& finite = check(r, Invariant::finite);
    EXPECT_FALSE(finite.held);
    ASSERT_TRUE(finite.first_t);
    EXPECT_NEAR(*finite.first_t, 0.1, 1e-12);
}

TEST(StressInvariants, SlowDownLateInTheRunIsCaught) {
    Scenario s = flight();
    s.dt = 1e-4;  // 10,000 states: 39 timing blocks
    const ScriptedSimulator slowing(free_flight, [](std::int64_t n) {
        if (n >= 6000) spin_for(std::chrono::microseconds(3));  // the cost of a subnormal-bound step
    });
    const StressResult r = run_double(s, slowing);
    EXPECT_EQ(r.outcome, StressOutcome::fail);
    const InvariantCheck& cost = check(r, Invariant::flat_cost);
    EXPECT_TRUE(cost.checked);
    EXPECT_FALSE(cost.held);
    EXPECT_GT(cost.worst, kCostRatioLimit);
    ASSERT_TRUE(cost.first_t);
    // The block that holds step 6000 starts at t = 0.5888, but only 144 of its
    // 256 steps are slow: whether it passes 4x the early cost depends on how
    // cheap a fast step is (under AddressSanitizer it often does not), so the
    // first wholly slow block, from step 6144 (t = 0.6144), is the bound. On a
    // loaded machine a preempted earlier block can be flagged first.
    EXPECT_LE(*cost.first_t, 0.6145);
}

TEST(StressInvariants, RunOverItsBudgetIsStopped) {
    const ScriptedSimulator stuck(free_flight, [](std::int64_t) { spin_for(std::chrono::microseconds(200)); });
    Scenario s = flight();
    s.duration = 100.0;  // 10,000 steps: 2 s at this cost, stopped after the first timing block
    const auto start = std::chrono::steady_clock::now();
    const StressResult r = run_double(s, stuck, 0.02);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
    EXPECT_EQ(r.outcome, StressOutcome::fail);
    const InvariantCheck& budget = check(r, Invariant::time_budget);
    EXPECT_FALSE(budget.held);
    ASSERT_TRUE(budget.first_t);
    EXPECT_LT(*budget.first_t, 100.0);
    EXPECT_GT(budget.first_value, 0.02);
}

TEST(StressInvariants, ThrowingSimulatorIsACrash) {
    const ScriptedSimulator throwing([](std::int64_t n, const Scenario& s) {
        if (n == 5) throw std::runtime_error("solver exploded");
        return free_flight(n, s);
    });
    const StressResult r = run_double(flight(), throwing);
    EXPECT_EQ(r.outcome, StressOutcome::crashed);
    EXPECT_NE(r.reason.find("solver exploded"), std::string::npos) << r.reason;
}

// --- worker processes: a crash or a hang costs its own run only ---

Scenario named(std::string name) {
    Scenario s = flight();
    s.name = std::move(name);
    return s;
}

TEST(StressWorkers, AnAbortingEngineCostsItsOwnRunOnly) {
    const ScriptedSimulator aborting([](std::int64_t n, const Scenario& s) {
        if (n == 3 && s.name == "doomed") std::abort();
        return free_flight(n, s);
    });
    const std::vector<StressCase> cases{{"a", named("a"), false}, {"doomed", named("doomed"), false},
                                        {"b", named("b"), false}};
    StressRequest request;
    request.simulators = {&aborting};
    request.jobs = 2;
    const StressReport report = run_stress(cases, request);
    ASSERT_EQ(report.results.size(), 3u);
    EXPECT_EQ(report.results[0].outcome, StressOutcome::pass) << report.results[0].reason;
    EXPECT_EQ(report.results[2].outcome, StressOutcome::pass) << report.results[2].reason;
    const StressResult& crashed = report.results[1];
    EXPECT_EQ(crashed.outcome, StressOutcome::crashed);
    EXPECT_EQ(crashed.reason.rfind("signal 6", 0), 0u) << crashed.reason;
    EXPECT_EQ(crashed.scenario, "doomed");
    EXPECT_EQ(crashed.simulator, "scripted");
    // What a worker computed crosses the pipe whole: the checks of a passing run.
    EXPECT_EQ(report.results[0].checks.size(), std::size(kInvariants));
    EXPECT_EQ(report.results[0].steps, 100);
}

TEST(StressWorkers, AStepThatNeverReturnsIsKilledAndHung) {
    const ScriptedSimulator stuck([](std::int64_t n, const Scenario& s) {
        if (n == 2 && s.name == "stuck")
            for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
        return free_flight(n, s);
    });
    const std::vector<StressCase> cases{{"stuck", named("stuck"), false}, {"a", named("a"), false}};
    StressRequest request;
    request.simulators = {&stuck};
    request.budget_seconds = 0.1;
    const auto start = std::chrono::steady_clock::now();
    const StressReport report = run_stress(cases, request);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
    EXPECT_DOUBLE_EQ(stress_deadline_seconds(0.1), 1.15);
    ASSERT_EQ(report.results.size(), 2u);
    EXPECT_EQ(report.results[0].outcome, StressOutcome::hung);
    EXPECT_NE(report.results[0].reason.find("over the limit of 1.15 s"), std::string::npos) << report.results[0].reason;
    EXPECT_EQ(report.results[1].outcome, StressOutcome::pass);
    EXPECT_NE(format_stress_matrix(report).find("HUNG"), std::string::npos);
    EXPECT_NE(format_stress_failures(report).find("stuck / scripted: hung: no result after"), std::string::npos)
        << format_stress_failures(report);
}

TEST(StressWorkers, AHungGeneratedScenarioIsWrittenForRun) {
    const StressCase generated{kMonteCarloRow, named("monte-carlo-0007"), true};
    StressReport report;
    report.rows = {kMonteCarloRow};
    report.simulators = {"scripted"};
    StressResult hung;
    hung.row = kMonteCarloRow;
    hung.scenario = "monte-carlo-0007";
    hung.simulator = "scripted";
    hung.outcome = StressOutcome::hung;
    hung.reason = "no result after 2 s, over the limit of 1.15 s";
    report.results = {hung};
    const fs::path dir = fs::temp_directory_path() / ("bouncecheck-stress-hung-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    write_stress(report, {generated}, nlohmann::json::object(), dir);
    EXPECT_TRUE(fs::exists(dir / kStressScenarioDir / "monte-carlo-0007.toml"));
    EXPECT_NE(test::slurp(dir / "stress.csv").find(",monte-carlo-0007,scripted,hung,"), std::string::npos);
    EXPECT_NE(format_stress_matrix(report).find("0/1 1H"), std::string::npos) << format_stress_matrix(report);
    fs::remove_all(dir);
}

// --- the generated families ---

TEST(StressMonteCarlo, EngineIsTheStandardsMt19937_64) {
    std::mt19937_64 g;  // default seed 5489
    g.discard(9999);
    EXPECT_EQ(g(), 9981545732273789042ull);  // [rand.predef]: the 10000th output
}

TEST(StressMonteCarlo, DeterministicAndSeeded) {
    const auto a = monte_carlo_scenarios(kMonteCarloSeed, 50);
    const auto b = monte_carlo_scenarios(kMonteCarloSeed, 50);
    const auto c = monte_carlo_scenarios(kMonteCarloSeed + 1, 50);
    ASSERT_EQ(a.size(), 50u);
    int differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(scenario_toml(a[i]), scenario_toml(b[i]));
        differ += scenario_toml(a[i]) != scenario_toml(c[i]);
    }
    EXPECT_EQ(differ, 50);
}

// A filtered set makes only the kept scenarios, each the same as in the
// whole set (--only monte-carlo-NNNN no longer builds the whole set).
TEST(StressMonteCarlo, AFilteredSetKeepsTheSameScenarios) {
    const auto all = monte_carlo_scenarios(kMonteCarloSeed, 50);
    const auto kept = monte_carlo_scenarios(kMonteCarloSeed, 50, [](const std::string& name) {
        return name == "monte-carlo-0007" || name == "monte-carlo-0049";
    });
    ASSERT_EQ(kept.size(), 2u);
    EXPECT_EQ(scenario_toml(kept[0]), scenario_toml(all[7]));
    EXPECT_EQ(scenario_toml(kept[1]), scenario_toml(all[49]));
    EXPECT_EQ(kept[1].description, all[49].description);
}

TEST(StressMonteCarlo, EveryScenarioIsValidAndRoundTrips) {
    const auto all = monte_carlo_scenarios(kMonteCarloSeed, kMonteCarloCount);
    ASSERT_EQ(all.size(), static_cast<std::size_t>(kMonteCarloCount));
    std::set<int> dims;
    int touching = 0, alpha0 = 0, alpha1 = 0, no_gravity = 0, tilted = 0;
    double dt_min = 1, dt_max = 0;
    for (const Scenario& s : all) {
        Scenario back;
        ASSERT_NO_THROW(back = parse_scenario(scenario_toml(s), s.name + ".toml")) << scenario_toml(s);
        EXPECT_EQ(back.dim, s.dim);
        for (int i = 0; i < s.dim; ++i) {
            EXPECT_EQ(back.room[i], s.room[i]);
            EXPECT_EQ(back.position[i], s.position[i]);
            EXPECT_EQ(back.velocity[i], s.velocity[i]);
            EXPECT_EQ(back.gravity[i], s.gravity[i]);
            touching += s.position[i] == s.radius || s.position[i] == s.room[i] - s.radius;
        }
        EXPECT_EQ(back.radius, s.radius);
        EXPECT_EQ(back.alpha, s.alpha);
        EXPECT_EQ(back.beta, s.beta);
        EXPECT_EQ(back.dt, s.dt);
        EXPECT_EQ(back.duration, s.duration);
        dims.insert(s.dim);
        alpha0 += s.alpha == 0;
        alpha1 += s.alpha == 1;
        no_gravity += s.gravity.isZero();
        tilted += s.gravity.head(s.dim - 1).norm() > 0;
        dt_min = std::min(dt_min, s.dt);
        dt_max = std::max(dt_max, s.dt);
        const double steps = s.duration / s.dt;
        EXPECT_GE(steps, 199.999);
        EXPECT_LE(steps, 2000.001);
    }
    // The set reaches the corners it is meant to.
    EXPECT_EQ(dims, (std::set<int>{2, 3}));
    EXPECT_GT(touching, 50);
    EXPECT_GT(alpha0, 50);
    EXPECT_GT(alpha1, 50);
    EXPECT_GT(no_gravity, 50);
    EXPECT_GT(tilted, 50);
    EXPECT_LT(dt_min, 5e-4);
    EXPECT_GT(dt_max, 0.03);
}

TEST(StressWallStarts, EveryWallInEveryMotion) {
    const auto all = wall_start_scenarios();
    ASSERT_EQ(all.size(), 30u);  // (4 + 6 walls) x (in, out, rest)
    std::set<std::string> names;
    for (const Scenario& s : all) {
        names.insert(s.name);
        EXPECT_NO_THROW(parse_scenario(scenario_toml(s), s.name));
        int touching = 0;
        for (int i = 0; i < s.dim; ++i) {
            const bool lower = s.position[i] == s.radius, upper = s.position[i] == s.room[i] - s.radius;
            if (!lower && !upper) continue;
            ++touching;
            const double into = lower ? -s.velocity[i] : s.velocity[i];
            if (s.name.ends_with("-in")) { EXPECT_GT(into, 0) << s.name; }
            if (s.name.ends_with("-out")) { EXPECT_LT(into, 0) << s.name; }
            if (s.name.ends_with("-rest")) { EXPECT_TRUE(s.velocity.isZero()) << s.name; }
        }
        EXPECT_EQ(touching, 1) << s.name;
    }
    EXPECT_EQ(names.size(), 30u);
}

// --- the bundled stress files ---

std::vector<fs::path> stress_files() {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(kStressDir))
        if (e.path().extension() == ".toml") files.push_back(e.path());
    return files;
}

TEST(StressFiles, LoadAndSayWhatTheyProbe) {
    const auto files = stress_files();
    ASSERT_GE(files.size(), 15u);
    std::set<std::string> names;
    for (const fs::path& f : files) {
        Scenario s;
        ASSERT_NO_THROW(s = load_scenario(f)) << f;
        EXPECT_EQ(s.name, f.stem().string());
        names.insert(s.name);
        const std::string text = test::slurp(f);
        EXPECT_TRUE(text.starts_with("# ")) << f << ": starts with the comment on what it probes";
        EXPECT_NE(text.find("sound"), std::string::npos) << f << ": says what a sound simulator must do";
    }
    EXPECT_EQ(names.size(), files.size());
    // Not picked up by `bouncecheck run`, which reads scenarios/*.toml only.
    for (const auto& e : fs::directory_iterator(BOUNCECHECK_SCENARIO_DIR))
        if (e.path().extension() == ".toml") {
            EXPECT_EQ(names.count(load_scenario(e.path()).name), 0u);
        }
}

TEST(StressFiles, FastBallsComeWithAndWithoutTheRemedies) {
    for (const char* speed : {"5", "20", "100"}) {
        const Scenario plain = load_scenario(kStressDir / fmt::format("fast-{}.toml", speed));
        const Scenario guarded = load_scenario(kStressDir / fmt::format("fast-{}-ccd.toml", speed));
        EXPECT_EQ(scenario_toml(plain).substr(scenario_toml(plain).find("[room]")),
                  scenario_toml(guarded).substr(scenario_toml(guarded).find("[room]")))
            << "the same ball";
        EXPECT_EQ(plain.engine_options("bullet").ccd, false);
        EXPECT_EQ(plain.engine_options("box2d").ccd, false);
        EXPECT_EQ(plain.engine_options("ode").substeps, 1);
        EXPECT_EQ(guarded.engine_options("bullet").ccd, true);
        EXPECT_EQ(guarded.engine_options("box2d").ccd, true);
        // ODE's substeps keep a step's travel under r/2.
        EXPECT_LT(guarded.velocity.norm() * guarded.dt / guarded.engine_options("ode").substeps, 0.5 * guarded.radius);
    }
}

// --- ccd and substeps in scenario files ---

constexpr std::string_view kBase = R"(name = "unit"
[room]
size = [1.0, 1.0]
[ball]
radius = 0.05
position = [0.5, 0.5]
velocity = [0.3, 0.1]
[world]
gravity = [0.0, -9.81]
[damping]
normal = 0.8
tangential = 0.99
[run]
dt = 0.03
duration = 1.0
)";

std::vector<Diagnostic> errors_of(const std::string& text) {
    try {
        parse_scenario(text, "t.toml");
    } catch (const ScenarioError& e) {
        return e.diagnostics();
    }
    ADD_FAILURE() << "accepted:\n" << text;
    return {};
}

TEST(StressOptions, CcdAndSubstepsAreRead) {
    const Scenario s = parse_scenario(std::string(kBase) + "[engines.bullet]\nccd = true\nsubsteps = 4\n"
                                                           "[engines.box2d]\nccd = false\n",
                                      "t.toml");
    EXPECT_EQ(s.engine_options("bullet").ccd, true);
    EXPECT_EQ(s.engine_options("bullet").substeps, 4);
    EXPECT_EQ(s.engine_options("box2d").ccd, false);
    EXPECT_EQ(s.engine_options("box2d").substeps, 1);
    EXPECT_FALSE(s.engine_options("ode").ccd.has_value());  // unset: the adapter's own choice
}

TEST(StressOptions, BadValuesAreLocated) {
    struct Case {
        std::string table, key, reason;
        int column;
    };
    for (const Case& c : {Case{"[engines.ode]\nccd = true\n", "engines.ode.ccd", "ODE has no continuous collision", 7},
                          Case{"[engines.mujoco]\nccd = true\n", "engines.mujoco.ccd", "MuJoCo has no continuous", 7},
                          Case{"[engines.chipmunk]\nccd = true\n", "engines.chipmunk.ccd", "Chipmunk has no continuous", 7},
                          Case{"[engines.bullet]\nccd = \"yes\"\n", "engines.bullet.ccd", "expected a boolean", 7},
                          Case{"[engines.box2d]\nsubsteps = 0\n", "engines.box2d.substeps", "within [1, 1000]", 12},
                          Case{"[engines.box2d]\nsubsteps = 2.0\n", "engines.box2d.substeps", "expected an integer", 12}}) {
        const auto d = errors_of(std::string(kBase) + c.table);
        ASSERT_EQ(d.size(), 1u) << c.table;
        EXPECT_EQ(d[0].file, "t.toml");
        EXPECT_EQ(d[0].key, c.key);
        EXPECT_EQ(d[0].line, 17);
        EXPECT_EQ(d[0].column, c.column);
        EXPECT_NE(d[0].reason.find(c.reason), std::string::npos) << d[0].format();
    }
}

#if defined(BOUNCECHECK_WITH_BULLET) && defined(BOUNCECHECK_WITH_ODE)
// What the stress suite measures: at 20 m/s and dt 0.03 the discrete engines
// find the ball beyond the wall; CCD (Bullet) and substeps (ODE) keep it in.
TEST(StressOptions, RemediesReachTheEnginesAndWork) {
    for (const char* engine : {"bullet", "ode"}) {
        const auto sim = test::find_simulator(engine);
        const StressResult plain = run_stress_case({"fast-20", load_scenario(kStressDir / "fast-20.toml")}, *sim, 30);
        const StressResult guarded =
            run_stress_case({"fast-20-ccd", load_scenario(kStressDir / "fast-20-ccd.toml")}, *sim, 30);
        EXPECT_FALSE(check(plain, Invariant::in_room).held) << engine;
        EXPECT_TRUE(check(guarded, Invariant::in_room).held) << engine << ": " << guarded.reason;
        EXPECT_EQ(guarded.outcome, StressOutcome::pass) << engine << ": " << guarded.reason;
        if (std::string(engine) == "bullet") {
            EXPECT_EQ(plain.ccd, "off (motion threshold 0)");
            EXPECT_TRUE(guarded.ccd.starts_with("motion threshold")) << guarded.ccd;
        } else {
            EXPECT_TRUE(plain.substeps.starts_with("1 engine step of 0.03 s")) << plain.substeps;
            EXPECT_TRUE(guarded.substeps.starts_with("32 engine steps of 0.0009375 s")) << guarded.substeps;
        }
    }
}
#endif

#ifdef BOUNCECHECK_WITH_BOX2D
TEST(StressOptions, Box2dCcdSwitchIsRecorded) {
    const auto sim = test::find_simulator("box2d");
    const StressResult plain = run_stress_case({"fast-5", load_scenario(kStressDir / "fast-5.toml")}, *sim, 30);
    const StressResult guarded = run_stress_case({"fast-5-ccd", load_scenario(kStressDir / "fast-5-ccd.toml")}, *sim, 30);
    EXPECT_EQ(plain.ccd, "off");
    EXPECT_TRUE(guarded.ccd.starts_with("on")) << guarded.ccd;
    EXPECT_FALSE(check(plain, Invariant::in_room).held);
    EXPECT_EQ(guarded.outcome, StressOutcome::pass) << guarded.reason;
}
#endif

// --- the command ---

class StressCli : public ::testing::Test {
protected:
    void SetUp() override {
        out_ = fs::temp_directory_path() / ("bouncecheck-stress-" + std::to_string(::getpid()));
        fs::remove_all(out_);
    }
    void TearDown() override { fs::remove_all(out_); }
    fs::path out_;
};

TEST_F(StressCli, MatrixAndFiles) {
    const auto r = test::bouncecheck("stress --engines reference,exact --only fast-20 wall-starts monte-carlo-0007 "
                                     "--jobs 2 --out " + out_.string());
    EXPECT_EQ(r.status, 0) << r.output;
    for (const char* row : {"fast-20 ", "wall-starts ", "monte-carlo "}) EXPECT_NE(r.output.find(row), std::string::npos) << row;
    EXPECT_NE(r.output.find("30/30"), std::string::npos) << r.output;  // the family as counts
    EXPECT_NE(r.output.find("1/1"), std::string::npos) << r.output;    // one Monte-Carlo scenario
    const auto json = nlohmann::json::parse(test::slurp(out_ / "stress.json"));
    EXPECT_EQ(json["schema"], kStressSchema);
    EXPECT_EQ(json["results"].size(), 2u * 32u);
    EXPECT_EQ(json["generated_scenarios"].size(), 31u);
    for (const auto& res : json["results"]) EXPECT_EQ(res["outcome"], "pass") << res.dump();
    const std::string csv = test::slurp(out_ / "stress.csv");
    EXPECT_TRUE(csv.starts_with("row,scenario,simulator,outcome,first_broken,"));
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 * 32);
}

// --monte-carlo and --seed choose the generated set; a larger set extends
// the default one, whose scenario 7 is the same in both.
TEST_F(StressCli, MonteCarloSizeAndSeed) {
    const auto r = test::bouncecheck("stress --engines exact --only monte-carlo --monte-carlo 1200 --out " +
                                     out_.string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("1200/1200"), std::string::npos) << r.output;
    const auto json = nlohmann::json::parse(test::slurp(out_ / "stress.json"));
    EXPECT_EQ(json["monte_carlo"]["count"], 1200);
    EXPECT_EQ(json["monte_carlo"]["seed"], kMonteCarloSeed);
    ASSERT_EQ(json["generated_scenarios"].size(), 1200u);
    EXPECT_EQ(json["generated_scenarios"][1199]["name"], "monte-carlo-1199");
    const Scenario seventh = monte_carlo_scenarios(kMonteCarloSeed, kMonteCarloCount)[7];
    EXPECT_EQ(json["generated_scenarios"][7]["dt"], seventh.dt);
    EXPECT_EQ(json["generated_scenarios"][7]["alpha"], seventh.alpha);

    const auto other = test::bouncecheck("stress --engines exact --only monte-carlo --monte-carlo 5 --seed 7 --out " +
                                         out_.string());
    EXPECT_EQ(other.status, 0) << other.output;
    const auto seeded = nlohmann::json::parse(test::slurp(out_ / "stress.json"));
    EXPECT_EQ(seeded["monte_carlo"]["seed"], 7);
    ASSERT_EQ(seeded["generated_scenarios"].size(), 5u);
    EXPECT_EQ(seeded["generated_scenarios"][3]["dt"], monte_carlo_scenarios(7, 5)[3].dt);
    EXPECT_EQ(test::bouncecheck("stress --monte-carlo -1 --out " + out_.string()).status, 2);
}

#ifdef BOUNCECHECK_WITH_BULLET
TEST_F(StressCli, BrokenInvariantExitsOneAndIsNamed) {
    const auto r = test::bouncecheck("stress --engines bullet --only fast-20 fast-20-ccd --out " + out_.string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("FAIL room"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("fast-20 / bullet: in_room broke at t = 0.03 s"), std::string::npos) << r.output;
    const std::string csv = test::slurp(out_ / "stress.csv");
    EXPECT_NE(csv.find("fast-20,fast-20,bullet,fail,in_room,0.0299"), std::string::npos) << csv;
    EXPECT_NE(csv.find("fast-20-ccd,fast-20-ccd,bullet,pass"), std::string::npos) << csv;
}
#endif

TEST_F(StressCli, FailedGeneratedScenariosAreWrittenForRun) {
    const Scenario broken = monte_carlo_scenarios(kMonteCarloSeed, 3)[2];
    const Scenario fine = monte_carlo_scenarios(kMonteCarloSeed, 3)[1];
    const std::vector<StressCase> cases{{kMonteCarloRow, fine, true}, {kMonteCarloRow, broken, true}};
    StressReport report;
    report.rows = {kMonteCarloRow};
    report.simulators = {"scripted"};
    report.results.resize(2);
    report.results[0] = {kMonteCarloRow, fine.name, "scripted", StressOutcome::pass, "", {}, 0, 0, "", ""};
    report.results[1] = {kMonteCarloRow, broken.name, "scripted", StressOutcome::fail, "in_room", {}, 0, 0, "", ""};
    fs::create_directories(out_);
    write_stress(report, cases, nlohmann::json::object(), out_);
    const fs::path file = out_ / kStressScenarioDir / (broken.name + ".toml");
    ASSERT_TRUE(fs::exists(file));
    EXPECT_FALSE(fs::exists(out_ / kStressScenarioDir / (fine.name + ".toml")));
    EXPECT_EQ(scenario_toml(load_scenario(file)).substr(0, 40), scenario_toml(broken).substr(0, 40));
    EXPECT_EQ(load_scenario(file).velocity, broken.velocity);
    EXPECT_EQ(test::bouncecheck("validate " + file.string()).status, 0);
}

// Determinism: every job count gives the same results, bit for bit, once the
// wall-clock columns (run_seconds, cost_ratio) are left out; a hash of what
// remains proves it.
TEST_F(StressCli, SameResultsForEveryJobCount) {
    auto digest_without_timings = [&](int jobs) {
        const fs::path dir = out_ / std::to_string(jobs);
#ifdef BOUNCECHECK_WITH_BOX2D
        const std::string engines = "reference,exact,box2d";  // box2d: an engine with global state
#else
        const std::string engines = "reference,exact";
#endif
        const auto r = test::bouncecheck("stress --engines " + engines + " --only wall-starts corner-2d elastic --jobs " +
                                         std::to_string(jobs) + " --out " + dir.string());
        EXPECT_LE(r.status, 1) << r.output;
        std::istringstream csv(test::slurp(dir / "stress.csv"));
        std::string line;
        std::getline(csv, line);
        std::vector<bool> timing;
        std::istringstream header(line);
        for (std::string name; std::getline(header, name, ',');) timing.push_back(name == "run_seconds" || name == "cost_ratio");
        std::uint64_t h = 1469598103934665603ull;
        std::size_t rows = 0;
        while (std::getline(csv, line)) {
            std::istringstream fields(line);
            std::size_t i = 0;
            for (std::string f; std::getline(fields, f, ','); ++i)
                if (i >= timing.size() || !timing[i])
                    for (unsigned char c : f + ",") h = (h ^ c) * 1099511628211ull;
            ++rows;
        }
        EXPECT_GE(rows, 3u * 14u);
        return h;
    };
    EXPECT_EQ(digest_without_timings(1), digest_without_timings(2));
}

// The hostile audit's finding 18: a million generated scenarios with --only
// picking one cost that one's memory (1.17 GB before), and name the run's
// generated range when the name is not in it.
TEST_F(StressCli, OnlyOneOfAMillionGeneratedScenariosStaysSmall) {
    const auto r = test::bouncecheck("stress --engines exact --only monte-carlo-0007 --monte-carlo 1000000 --out " +
                                     out_.string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("1/1"), std::string::npos) << r.output;
    rusage children{};
    ::getrusage(RUSAGE_CHILDREN, &children);  // the largest child this test waited for: that run
    EXPECT_LT(children.ru_maxrss, 300 * 1024) << "KiB";
    const auto missing = test::bouncecheck("stress --only monte-carlo-0012 --monte-carlo 10 --out " + out_.string());
    EXPECT_EQ(missing.status, 2);
    EXPECT_NE(missing.output.find("generated: monte-carlo-0000 to monte-carlo-0009"), std::string::npos)
        << missing.output;
}

TEST_F(StressCli, BadInputExitsTwo) {
    EXPECT_EQ(test::bouncecheck("stress --only no-such-row --out " + out_.string()).status, 2);
    EXPECT_EQ(test::bouncecheck("stress --engines warp --out " + out_.string()).status, 2);
    EXPECT_EQ(test::bouncecheck("stress --jobs 0 --out " + out_.string()).status, 2);
    EXPECT_FALSE(fs::exists(out_ / "stress.json"));
}

}  // namespace
