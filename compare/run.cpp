#include "compare/run.h"

#include "compare/trajectory_csv.h"
#include "reference/simulators.h"

#include <fmt/format.h>

#include <algorithm>
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
    ScenarioRun run;
    run.scenario = s;
    const ExactModel exact(s);
    const SimulatorSummary reference = make_reference_simulator()->run(s, nullptr);
    const SimulatorSummary exact_summary = make_exact_simulator()->run(s, nullptr);
    if (request.plots) {
        run.exact_path = exact_plot_trace(exact, s);
        run.exact_apexes = exact_summary.apexes;
    }
    const std::int64_t states = expected_states(s);

    for (const Simulator* sim : request.simulators) {
        SimulatorSummary result;
        result.simulator = std::string(sim->name());
        if (auto why = sim->cannot_run(s)) {
            result.status = RunStatus::skipped;
            result.reason = *why;
            run.results.push_back(result);
            run.comparisons.emplace_back();
            if (request.plots) run.plots.emplace_back();
            continue;
        }
        TrajectoryComparer comparer(s, exact, reference.rest_time, exact_summary.rest_time);
        std::optional<TraceDecimator> trace;
        if (request.plots) {
            trace.emplace(states);
            comparer.record_series(std::max<std::int64_t>(1, states / static_cast<std::int64_t>(kPlotPoints)));
        }
        try {
            std::optional<TrajectoryCsv> csv;
            std::filesystem::path relative;
            if (request.trajectories) {
                relative = std::filesystem::path(s.name) / (result.simulator + ".csv");
                std::filesystem::create_directories(request.out_dir / s.name);
                csv.emplace(request.out_dir / relative, s.dim);
            }
            TeeSink sink{csv ? &*csv : nullptr, &comparer, trace ? &*trace : nullptr};
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
        if (trace) {
            ScenarioRun::SimulatorPlot plot;
            // exact's own samples sit on the document clock; its plotted path
            // has the contacts at their instants instead.
            plot.path = result.simulator == "exact" ? run.exact_path : trace->finish();
            plot.divergence_t = comparer.reference_series()->times();
            plot.divergence = comparer.reference_series()->values();
            plot.error_t = comparer.exact_series()->times();
            plot.error = comparer.exact_series()->values();
            run.plots.push_back(std::move(plot));
        }
        run.results.push_back(std::move(result));
        run.comparisons.push_back(std::move(c));
    }
    return run;
}

}  // namespace bouncecheck
