// Which engine of a scenario is closest to exact and which to the
// reference, on the figures that rank them (docs/comparison.md, "What the
// report leads with"): the largest apex-height error and floor-contact time
// error over the compared bounces, and how long the path stays within the
// tracking tolerance. A whole-run RMS ranks nothing here: it is dominated by
// one shifted event or by sliding after rest.
#pragma once

#include "metrics/summary.h"
#include "verdicts/verdicts.h"

#include <optional>
#include <string>
#include <vector>

namespace bouncecheck {

// The best value of one figure and every simulator that reaches it (ties together).
struct Leader {
    std::vector<std::string> simulators;
    double value = 0;
    bool whole_run = false;  // tracks_exact: never left the tolerance (value then 0)
};

// Engines only: the baselines (reference and exact) and the simulators that
// failed or were skipped are not ranked. Empty where no engine has the figure.
struct ScenarioRanking {
    std::optional<Leader> apex_error;       // smallest vs_exact.bounce_height_rel_max
    std::optional<Leader> contact_error;    // smallest vs_exact.contact_time_max
    std::optional<Leader> tracks_exact;     // latest vs_exact.trajectory.first_exceeds (never: whole run)
    std::optional<Leader> apex_divergence;  // smallest vs_reference.bounce_height_rel_max
    bool empty() const { return !apex_error && !contact_error && !tracks_exact && !apex_divergence; }
};

// `comparisons` is parallel to `results` (empty for a skipped simulator).
ScenarioRanking rank_simulators(const std::vector<SimulatorSummary>& results,
                                const std::vector<std::optional<Comparison>>& comparisons);

}  // namespace bouncecheck
