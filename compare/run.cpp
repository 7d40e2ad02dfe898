#include "compare/run.h"

#include "compare/trajectory_csv.h"
#include "reference/simulators.h"

#include <fmt/format.h>

#include <optional>

namespace bouncecheck {

ThresholdSet limits_for(const Scenario& s, const std::string& simulator, const ThresholdSet& overrides) {
    if (simulator == "reference") {
        const auto it = s.thresholds.simulator.find("reference");
        const ThresholdSet own = it == s.thresholds.simulator.end() ? ThresholdSet{} : it->second;
        return own.overridden_by(overrides);
    }
    return s.thresholds.for_simulator(simulator).overridden_by(overrides);
}

ScenarioRun run_scenario(const Scenario& s, const RunRequest& request) {
    ScenarioRun run{s, {}, {}};
    const ExactModel exact(s);
    const SimulatorSummary reference = make_reference_simulator()->run(s, nullptr);
    const SimulatorSummary exact_summary = make_exact_simulator()->run(s, nullptr);

    for (const Simulator* sim : request.simulators) {
        SimulatorSummary result;
        result.simulator = std::string(sim->name());
        if (auto why = sim->cannot_run(s)) {
            result.status = RunStatus::skipped;
            result.reason = *why;
            run.results.push_back(result);
            run.comparisons.emplace_back();
            continue;
        }
        TrajectoryComparer comparer(s, exact, reference.rest_time, exact_summary.rest_time);
        try {
            std::optional<TrajectoryCsv> csv;
            std::filesystem::path relative;
            if (request.trajectories) {
                relative = std::filesystem::path(s.name) / (result.simulator + ".csv");
                std::filesystem::create_directories(request.out_dir / s.name);
                csv.emplace(request.out_dir / relative, s.dim);
            }
            TeeSink sink(csv ? &*csv : nullptr, &comparer);
            result = sim->run(s, &sink);
            if (csv) {
                csv->commit();
                result.trajectory_file = relative.string();
            }
        } catch (const std::exception& e) {
            result.status = RunStatus::failed;
            result.reason = fmt::format("exception: {}", e.what());
        }

        const ThresholdSet limits = limits_for(s, result.simulator, request.threshold_overrides);
        const int bounce_count = limits.bounce_count.value_or(kDefaultBounceCount);
        Comparison c;
        c.vs_reference = compare_bounces(result, reference, bounce_count, s);
        c.vs_reference.trajectory = comparer.vs_reference();
        c.vs_exact = compare_bounces(result, exact_summary, bounce_count, s);
        c.vs_exact.trajectory = comparer.vs_exact();
        c.damping = check_damping(result, s, limits);
        c.thresholds = check_thresholds(c, limits, s);
        run.results.push_back(std::move(result));
        run.comparisons.push_back(std::move(c));
    }
    return run;
}

}  // namespace bouncecheck
