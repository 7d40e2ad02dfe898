// One scenario through every selected simulator, compared with the reference
// and with exact: what `bouncecheck run` does per scenario.
#pragma once

#include "reports/run_report.h"
#include "scenarios/scenario.h"
#include "simulators/simulator.h"

#include <filesystem>
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

// Runs the baselines (reference and exact) first, then each selected
// simulator with its stream compared as it runs. A simulator that throws is
// recorded as failed; the others still run.
ScenarioRun run_scenario(const Scenario& s, const RunRequest& request);

}  // namespace bouncecheck
