// The verdicts on a simulator's comparison: does it reproduce the damping
// law (measured alpha and beta against the scenario's), and does it hold the
// scenario's CI thresholds.
#pragma once

#include "comparison/comparison.h"
#include "metrics/summary.h"
#include "scenarios/scenario.h"

#include <string>
#include <vector>

namespace bouncecheck {

// Defaults where the scenario sets no threshold.
inline constexpr int kDefaultBounceCount = 5;
inline constexpr double kDefaultDampingTolerance = 0.02;  // for the damping verdict
inline constexpr double kMinSpeedInSteps = 30;  // damping: contacts slower than this x |g| dt are not measured

// Measured damping against the law's alpha and beta, over the contacts
// before the simulator's rest that hit the wall faster than 30 |g| dt
// (slower ones measure one step of gravity as much as the damping).
struct DampingCheck {
    int contacts = 0, tangential_contacts = 0;
    double normal_mean = 0, normal_worst = 0;  // measured coefficient; worst = farthest from alpha
    double tangential_mean = 0, tangential_worst = 0;
    double normal_tolerance = kDefaultDampingTolerance, tangential_tolerance = kDefaultDampingTolerance;
    bool reproduces = true;
    std::string verdict;  // "reproduces the damping law" or what differs
};

struct ThresholdCheck {
    std::string metric;  // a [thresholds] key
    double measured = 0, limit = 0;
    bool passed = true;
};

// A simulator against both baselines, and the verdicts on it: one row of a report.
struct Comparison {
    Divergence vs_reference, vs_exact;
    DampingCheck damping;
    std::vector<ThresholdCheck> thresholds;  // empty when none is set for this simulator
    bool passed() const;
};

// The contacts the damping check measures: before the simulator's rest, and
// faster than kMinSpeedInSteps |g| dt.
std::vector<ContactEvent> damping_contacts(const SimulatorSummary& self, const Scenario& s);

DampingCheck check_damping(const SimulatorSummary& self, const Scenario& s, const ThresholdSet& limits);

// The scenario's thresholds for this simulator, evaluated on its comparison.
std::vector<ThresholdCheck> check_thresholds(const Comparison& c, const ThresholdSet& limits, const Scenario& s);

// The limits that apply to `simulator`: the scenario's [thresholds], its
// [thresholds.<simulator>], then the command line's. The reference is the
// baseline: only a [thresholds.reference] table (or the command line) gates it.
ThresholdSet limits_for(const Scenario& s, const std::string& simulator, const ThresholdSet& overrides);

}  // namespace bouncecheck
