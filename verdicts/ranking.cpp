#include "verdicts/ranking.h"

#include <cmath>
#include <functional>
#include <limits>

namespace bouncecheck {

namespace {

// The leader of one figure: `figure` gives a simulator's value (none if it
// has none), the smallest wins unless `larger`.
std::optional<Leader> leader(const std::vector<SimulatorSummary>& results,
                             const std::vector<std::optional<Comparison>>& comparisons,
                             const std::function<std::optional<double>(const Comparison&)>& figure, bool larger) {
    std::optional<Leader> best;
    for (std::size_t i = 0; i < results.size() && i < comparisons.size(); ++i) {
        const SimulatorSummary& r = results[i];
        const auto& c = comparisons[i];
        if (r.status != RunStatus::ok || !c) continue;
        if (r.simulator == c->vs_exact.baseline || r.simulator == c->vs_reference.baseline) continue;
        const std::optional<double> value = figure(*c);
        if (!value || std::isnan(*value)) continue;
        if (!best || (larger ? *value > best->value : *value < best->value)) best = Leader{{r.simulator}, *value};
        else if (*value == best->value) best->simulators.push_back(r.simulator);
    }
    return best;
}

}  // namespace

ScenarioRanking rank_simulators(const std::vector<SimulatorSummary>& results,
                                const std::vector<std::optional<Comparison>>& comparisons) {
    constexpr double kNever = std::numeric_limits<double>::infinity();
    ScenarioRanking ranking;
    ranking.apex_error = leader(
        results, comparisons,
        [](const Comparison& c) -> std::optional<double> {
            if (c.vs_exact.bounces.empty()) return std::nullopt;
            return c.vs_exact.bounce_height_rel_max;
        },
        false);
    ranking.contact_error = leader(
        results, comparisons, [](const Comparison& c) { return c.vs_exact.contact_time_max; }, false);
    ranking.tracks_exact = leader(
        results, comparisons,
        [&](const Comparison& c) -> std::optional<double> {
            if (c.vs_exact.trajectory.samples == 0) return std::nullopt;
            return c.vs_exact.trajectory.first_exceeds.value_or(kNever);  // never leaving ranks above any time
        },
        true);
    if (ranking.tracks_exact && ranking.tracks_exact->value == kNever) {
        ranking.tracks_exact->whole_run = true;
        ranking.tracks_exact->value = 0;
    }
    ranking.apex_divergence = leader(
        results, comparisons,
        [](const Comparison& c) -> std::optional<double> {
            if (c.vs_reference.bounces.empty()) return std::nullopt;
            return c.vs_reference.bounce_height_rel_max;
        },
        false);
    return ranking;
}

}  // namespace bouncecheck
