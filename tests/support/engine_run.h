// Test helper: runs a built simulator through the real path (the same
// run() and trajectory CSV as `bouncecheck run --trajectories`) and returns
// its summary and every state.
#pragma once

#include "metrics/summary.h"
#include "registry/registry.h"
#include "reports/trajectory_csv.h"
#include "simulators/simulator.h"
#include "tests/support/csv.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

namespace bouncecheck::test {

struct SimulatorRun {
    SimulatorSummary summary;
    std::vector<State> states;
};

inline std::unique_ptr<const Simulator> find_simulator(const std::string& name) {
    for (auto& sim : built_simulators())
        if (sim->name() == name) return std::move(sim);
    throw std::runtime_error("simulator not built: " + name);
}

inline SimulatorRun run_simulator(const std::string& name, const Scenario& s) {
    const auto sim = find_simulator(name);
    const auto path = std::filesystem::temp_directory_path() /
                      ("bouncecheck-" + name + "-" + std::to_string(::getpid()) + ".csv");
    SimulatorRun run;
    {
        TrajectoryCsv csv(path, s.dim);
        run.summary = record_run(*sim, s, &csv);
        csv.commit();
    }
    const Csv csv = read_csv(path.string());
    std::filesystem::remove(path);
    for (const auto& row : csv.rows) {
        State st;
        st.t = row[0];
        for (int i = 0; i < s.dim; ++i) {
            st.p[i] = row[1 + i];
            st.v[i] = row[1 + s.dim + i];
        }
        run.states.push_back(st);
    }
    return run;
}

}  // namespace bouncecheck::test
