// An engine that aborts, crashes or hangs on to the process costs only its
// own result when engines run in worker processes (RunRequest::isolate).
#include "commands/run/run_pipeline.h"
#include "exact/exact_simulator.h"
#include "reference/reference_simulator.h"
#include "scenarios/loader.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace bouncecheck {
namespace {

// A stand-in for an engine library that asserts on its input.
class AbortingEngine final : public Simulator {
public:
    std::string_view name() const override { return "aborting"; }
    std::string_view description() const override { return "aborts in the middle of its run"; }
    bool third_party() const override { return true; }
    RunOutcome run(const Scenario&, RunSink& sink) const override {
        sink.on_state(State{}, ContactMask{});
        std::fprintf(stderr, "btAssert: broadphase proxy out of range\n");
        std::abort();
    }
};

Scenario seed_2d() { return load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-2d.toml"); }

TEST(Isolation, AnAbortingEngineFailsAloneWithItsSignalAndLastWords) {
    const auto reference = make_reference_simulator();
    const auto exact = make_exact_simulator();
    const AbortingEngine aborting;
    RunRequest request{{reference.get(), &aborting, exact.get()}, {}, false, {}, true};
    request.isolate = true;
    const ScenarioRun run = run_scenario(seed_2d(), request);

    ASSERT_EQ(run.results.size(), 3u);
    EXPECT_EQ(run.results[0].status, RunStatus::ok);
    EXPECT_EQ(run.results[2].status, RunStatus::ok);
    EXPECT_GT(run.results[2].contacts, 10);
    const SimulatorSummary& failed = run.results[1];
    EXPECT_EQ(failed.simulator, "aborting");
    EXPECT_EQ(failed.status, RunStatus::failed);
    EXPECT_NE(failed.reason.find("signal 6"), std::string::npos) << failed.reason;
    EXPECT_NE(failed.reason.find("btAssert: broadphase proxy out of range"), std::string::npos) << failed.reason;
    // Its row is still complete enough for every report: a comparison and a (empty) plot.
    ASSERT_TRUE(run.comparisons[1]);
    ASSERT_EQ(run.plots.size(), 3u);
    EXPECT_TRUE(run.plots[1]);
}

TEST(Isolation, AnIsolatedRunGivesTheSameResultAsInProcess) {
    // Everything crosses the pipe bit for bit: the reference, forced through
    // a child here by a wrapper that calls itself third-party.
    struct Wrapped final : Simulator {
        std::unique_ptr<const Simulator> inner = make_reference_simulator();
        std::string_view name() const override { return inner->name(); }
        std::string_view description() const override { return inner->description(); }
        bool third_party() const override { return true; }
        RunOutcome run(const Scenario& s, RunSink& sink) const override { return inner->run(s, sink); }
    } wrapped;
    const Scenario s = seed_2d();
    RunRequest request{{&wrapped}, {}, false, {}, true};
    const ScenarioRun in_process = run_scenario(s, request);
    request.isolate = true;
    const ScenarioRun isolated = run_scenario(s, request);

    RunReport a, b;
    a.scenarios.push_back(in_process);
    b.scenarios.push_back(isolated);
    for (RunReport* r : {&a, &b}) r->scenarios[0].results[0].run_seconds = 0;  // the one wall-clock figure
    EXPECT_EQ(to_json(a), to_json(b));
    EXPECT_EQ(to_html(a).text(), to_html(b).text());
}

// Never returns from its run: a step stuck in an engine's solver.
class HangingEngine final : public Simulator {
public:
    std::string_view name() const override { return "hanging"; }
    std::string_view description() const override { return "never returns from its run"; }
    bool third_party() const override { return true; }
    RunOutcome run(const Scenario&, RunSink& sink) const override {
        sink.on_state(State{}, ContactMask{});
        for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
    }
};

TEST(Isolation, AHangingEngineIsKilledAtTheBudgetAndFailsAsHung) {
    const auto reference = make_reference_simulator();
    const HangingEngine hanging;
    RunRequest request{{&hanging, reference.get()}, {}, false, {}, true};
    request.isolate = true;
    request.budget_seconds = 0.3;
    const auto start = std::chrono::steady_clock::now();
    const ScenarioRun run = run_scenario(seed_2d(), request);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
    ASSERT_EQ(run.results.size(), 2u);
    EXPECT_EQ(run.results[0].status, RunStatus::failed);
    EXPECT_EQ(run.results[0].reason.rfind("hung: no result after", 0), 0u) << run.results[0].reason;
    EXPECT_NE(run.results[0].reason.find("over the limit of 0.3 s"), std::string::npos) << run.results[0].reason;
    EXPECT_EQ(run.results[1].status, RunStatus::ok);
}

}  // namespace
}  // namespace bouncecheck
