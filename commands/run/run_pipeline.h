// One scenario through every selected simulator, compared with the reference
// and with exact: what `bouncecheck run` does per scenario.
#pragma once

#include "comparison/comparison.h"
#include "exact/exact_model.h"
#include "reports/run_report.h"
#include "scenarios/scenario.h"
#include "simulators/simulator.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

namespace bouncecheck {

struct RunRequest {
    std::vector<const Simulator*> simulators;  // the report's rows, in order
    std::filesystem::path out_dir;             // trajectories go to out_dir/<scenario>/<simulator>.csv
    bool trajectories = false;
    ThresholdSet threshold_overrides;  // from the command line: over the scenario's, for every simulator
    bool plots = false;  // record what report.html draws (decimated paths, distances over time)
    // Run the engines (Simulator::third_party) in worker processes
    // (run_pairs_in_parallel), `jobs` at once, so that an engine that aborts
    // costs only its own result.
    bool isolate = false;
    int jobs = 0;  // worker processes; 0: every core
    // With isolate: an engine still running after this many seconds is
    // killed with its worker and fails as hung. 0: no limit.
    double budget_seconds = 0;
};

// One simulator's run, recorded and compared with the baselines as it
// streams: what the comparison's verdicts are made from (run_scenario).
struct ComparedRun {
    SimulatorSummary summary;
    TrajectoryDivergence vs_reference, vs_exact;
    std::optional<ScenarioRun::SimulatorPlot> plot;  // with request.plots
};

// What every simulator of a scenario is compared with, run once per scenario
// for the request's rows.
struct Baselines {
    Baselines(const Scenario& s, const RunRequest& request);
    ExactModel exact;
    SimulatorSummary exact_summary;
    PlotTrace exact_path;  // exact's path with its contacts at their instants (plots only)
    // TrajectoryComparer::share_baselines, when two or more rows besides the
    // reference's read it: for one, it would be made and read once.
    std::shared_ptr<const BaselineTrack> track;
    SimulatorSummary reference;
    // The reference's own row, compared as its baseline run streams (the
    // reference is run once, not again for its row), when the request has it.
    std::optional<ComparedRun> reference_row;
};
// Writes the trajectory if the request asks; an exception is a failed run.
// Public for bench/bench_comparison.cpp, which times it against the
// simulator's unrecorded run.
ComparedRun run_compared(const Simulator& sim, const Scenario& s, const RunRequest& request, const Baselines& base);

// Runs the baselines (reference and exact) first, then each selected
// simulator with its stream compared as it runs. A simulator that throws is
// recorded as failed; the others still run.
ScenarioRun run_scenario(const Scenario& s, const RunRequest& request);

// The run's exit status from its verdict (commands/command.h: the contract):
// 3 a simulator failed, else 1 a threshold was exceeded or the baseline
// changed, else 0.
int run_exit_status(const RunVerdict& verdict);

}  // namespace bouncecheck
