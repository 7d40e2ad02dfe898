// Comparisons: a simulator against itself, against known shifted copies,
// against a different damping law; thresholds gate the exit status.
#include "commands/run/run_pipeline.h"
#include "engines/engine.h"
#include "reference/reference_model.h"
#include "reference/reference_simulator.h"
#include "scenarios/loader.h"
#include "tests/support/cli.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace bouncecheck {
namespace {

Scenario seed3d() {
    // Without the bundled engine settings and thresholds: each test sets its own.
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-3d.toml");
    s.engines.clear();
    s.thresholds = {};
    return s;
}

// A stand-in engine: the reference model of a modified scenario, its centre shifted by `offset`.
std::unique_ptr<const Simulator> shifted_reference(const std::string& name, Vec3 offset, double alpha = -1) {
    EngineDefinition d;
    d.identity = {name, "test stand-in", 1000};
    d.build = [offset, alpha](const Scenario& s, const EngineOptions&,
                              std::vector<Setting>&) -> std::unique_ptr<EngineWorld> {
        struct World final : EngineWorld {
            World(const Scenario& s, Vec3 offset) : model(s), offset(offset) {}
            void step() override { model.step(); }
            void read(State& out) const override {
                out = model.state();
                out.p += offset;
            }
            ReferenceModel<3> model;
            Vec3 offset;
        };
        Scenario changed = s;
        if (alpha >= 0) changed.alpha = alpha;
        return std::make_unique<World>(changed, offset);
    };
    return make_engine_simulator(std::move(d));
}

ScenarioRun run_with(const Scenario& s, std::vector<const Simulator*> sims) {
    return run_scenario(s, RunRequest{std::move(sims), std::filesystem::temp_directory_path(), false, {}});
}

TEST(Comparison, ReferenceAgainstItselfHasZeroDivergence) {
    const Scenario s = seed3d();
    const auto reference = make_reference_simulator();
    const ScenarioRun run = run_with(s, {reference.get()});
    ASSERT_TRUE(run.comparisons[0].has_value());
    const Comparison& c = *run.comparisons[0];
    EXPECT_EQ(c.vs_reference.trajectory.rms, 0.0);
    EXPECT_EQ(c.vs_reference.trajectory.max, 0.0);
    EXPECT_EQ(c.vs_reference.trajectory.samples, 1401);
    EXPECT_FALSE(c.vs_reference.trajectory.first_exceeds.has_value());
    // Its row is its baseline run (Baselines), cut at its own rest.
    ASSERT_TRUE(run.results[0].rest_time.has_value());
    EXPECT_EQ(c.vs_reference.trajectory.rest_cut, run.results[0].rest_time);
    EXPECT_EQ(run.results[0].steps, 1400);
    ASSERT_EQ(c.vs_reference.bounces.size(), static_cast<size_t>(kDefaultBounceCount));
    EXPECT_EQ(c.vs_reference.bounce_height_rel_max, 0.0);
    EXPECT_GT(c.vs_exact.trajectory.rms, 0.0);  // the reference's own error at dt = 0.03
    EXPECT_TRUE(c.thresholds.empty());
}

TEST(Comparison, ShiftedCopyDivergesByTheShift) {
    const Scenario s = seed3d();
    const auto sideways = shifted_reference("ode", Vec3(0.001, 0, 0));
    const auto upwards = shifted_reference("bullet", Vec3(0, 0, 0.002));
    const ScenarioRun run = run_with(s, {sideways.get(), upwards.get()});
    // Every sample but the initial one (the scenario's own state) is shifted.
    const double shifted_fraction = std::sqrt(1400.0 / 1401.0);
    const Comparison& side = *run.comparisons[0];
    EXPECT_NEAR(side.vs_reference.trajectory.rms, 0.001 * shifted_fraction, 1e-12);
    EXPECT_NEAR(side.vs_reference.trajectory.max, 0.001, 1e-12);
    EXPECT_EQ(side.vs_reference.bounce_height_rel_max, 0.0);  // a sideways shift leaves apexes alone
    const Comparison& up = *run.comparisons[1];
    EXPECT_NEAR(up.vs_reference.trajectory.rms, 0.002 * shifted_fraction, 1e-12);
    for (const BounceDiff& b : up.vs_reference.bounces) {
        EXPECT_NEAR(b.abs_diff, 0.002, 1e-9) << "bounce " << b.index;
        EXPECT_NEAR(b.rel_diff, 0.002 / (b.baseline_height - s.radius), 1e-9) << "bounce " << b.index;
    }
}

TEST(Comparison, DivergenceTimeIsTheFirstSampleBeyondTheTolerance) {
    const Scenario s = seed3d();
    const auto far = shifted_reference("ode", Vec3(0.02, 0, 0));
    const ScenarioRun run = run_with(s, {far.get()});
    ASSERT_TRUE(run.comparisons[0]->vs_reference.trajectory.first_exceeds.has_value());
    EXPECT_EQ(*run.comparisons[0]->vs_reference.trajectory.first_exceeds, s.dt);  // the first engine step
}

TEST(Comparison, DampingVerdictNamesTheDifferingCoefficient) {
    Scenario s = seed3d();
    s.dt = 1e-3;  // measured coefficients then carry little of a step's gravity
    const auto faithful = make_reference_simulator();
    const auto soft = shifted_reference("ode", Vec3::Zero(), /*alpha=*/0.5);
    const ScenarioRun run = run_with(s, {faithful.get(), soft.get()});
    const DampingCheck& good = run.comparisons[0]->damping;
    EXPECT_TRUE(good.reproduces) << good.verdict;
    EXPECT_NEAR(good.normal_mean, 0.8, 0.01);
    EXPECT_NEAR(good.tangential_mean, 0.99, 0.01);
    const DampingCheck& bad = run.comparisons[1]->damping;
    EXPECT_FALSE(bad.reproduces);
    EXPECT_NE(bad.verdict.find("normal coefficient"), std::string::npos) << bad.verdict;
    EXPECT_NEAR(bad.normal_mean, 0.5, 0.02);
}

TEST(Comparison, SequencesOfDifferentLengthsAreComparedAsFarAsBothGo) {
    Scenario s = seed3d();
    const auto dead = shifted_reference("ode", Vec3::Zero(), /*alpha=*/0.0);  // stops at the first floor contact
    ThresholdSet limits;
    limits.bounce_count = 5;
    s.thresholds.all = limits;
    const ScenarioRun run = run_with(s, {dead.get()});
    const Comparison& c = *run.comparisons[0];
    EXPECT_LT(c.vs_reference.bounces.size(), 5u);
    EXPECT_NE(c.vs_reference.note.find("of the 5 bounces asked"), std::string::npos) << c.vs_reference.note;
    ASSERT_EQ(c.thresholds.size(), 1u);
    EXPECT_EQ(c.thresholds[0].metric, "bounce_count");
    EXPECT_FALSE(c.passed());
}

TEST(Comparison, ThresholdsPassAndFailPerSimulator) {
    Scenario s = seed3d();
    s.thresholds.all.trajectory_rms = 0.005;
    s.thresholds.simulator["bullet"].trajectory_rms = 0.0001;
    const auto a = shifted_reference("ode", Vec3(0.001, 0, 0));
    const auto b = shifted_reference("bullet", Vec3(0.001, 0, 0));
    const ScenarioRun run = run_with(s, {a.get(), b.get()});
    EXPECT_TRUE(run.comparisons[0]->passed());
    ASSERT_EQ(run.comparisons[1]->thresholds.size(), 1u);
    EXPECT_EQ(run.comparisons[1]->thresholds[0].metric, "trajectory_rms");
    EXPECT_NEAR(run.comparisons[1]->thresholds[0].measured, 0.001 * std::sqrt(1400.0 / 1401.0), 1e-12);
    EXPECT_EQ(run.comparisons[1]->thresholds[0].limit, 0.0001);
    EXPECT_FALSE(run.comparisons[1]->passed());
}

// ---- exit status and reports, end to end through the command

TEST(ComparisonCli, TightenedThresholdExits1AndEveryReportNamesEngineAndMetric) {
    const auto dir = std::filesystem::temp_directory_path() / ("bouncecheck-thr-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::string text = test::slurp(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-3d.toml");
    text = text.substr(0, text.find("\n# CI limits"));  // the bundled thresholds are replaced
    text += "\n[thresholds]\ntrajectory_rms = 1.0\n\n[thresholds.exact]\ntrajectory_rms = 1e-6\n";
    std::ofstream(dir / "tight.toml") << text;

    test::CliResult r = test::bouncecheck("run " + (dir / "tight.toml").string() + " --engines reference,exact --out " + (dir / "o").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("trajectory_rms"), std::string::npos) << r.output;
    const auto report = nlohmann::json::parse(test::slurp(dir / "o" / "report.json"));
    const auto& exact = report["scenarios"][0]["simulators"][1];
    EXPECT_EQ(exact["simulator"], "exact");
    EXPECT_EQ(exact["comparison"]["passed"], false);
    EXPECT_EQ(exact["comparison"]["thresholds"][0]["metric"], "trajectory_rms");
    const std::string md = test::slurp(dir / "o" / "report.md"), junit = test::slurp(dir / "o" / "junit.xml");
    EXPECT_NE(md.find("trajectory_rms"), std::string::npos);
    EXPECT_NE(junit.find("exact"), std::string::npos);
    EXPECT_NE(junit.find("<failure"), std::string::npos);
    EXPECT_NE(junit.find("trajectory_rms"), std::string::npos);

    // The command line loosens it again: exit 0, and a bad override is usage error 2.
    r = test::bouncecheck("run " + (dir / "tight.toml").string() + " --engines reference,exact --threshold trajectory_rms=1 --out " +
                    (dir / "o").string());
    EXPECT_EQ(r.status, 0) << r.output;
    r = test::bouncecheck("run " + (dir / "tight.toml").string() + " --threshold warp=1 --out " + (dir / "o").string());
    EXPECT_EQ(r.status, 2) << r.output;
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace bouncecheck
