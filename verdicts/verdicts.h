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
inline constexpr double kDefaultDampingTolerance = 0.02;  // restitution_abs, tangential_abs
// tangential_loss_rel: the mean tangential loss within a quarter of the law's
// (1 - beta), which tells beta = 0.99 from 1 (no loss) and from 0.97.
inline constexpr double kDefaultTangentialLossTolerance = 0.25;
// The law's loss that tangential_loss_rel is relative to, at least this
// (beta = 1 has none: a loss of 0.0025 is then a quarter of 0.01).
inline constexpr double kMinTangentialLossScale = 0.01;

// The slowest contact the damping check measures: 30 |g| dt. The
// impact-instant measure itself needs only that no second impact shares the
// contact's step (alpha v > |g| dt / 2): it reads an event-driven simulator
// exactly at any speed above that. An engine's samples place its impact
// within the step only as well as its penetration or skin allows (a ball
// found inside the wall has travelled up to v dt past it), so its measured
// coefficients carry up to (1 + alpha) |g| dt / v of one step's gravity:
// 6% at 30 |g| dt, and micro-bounces of a few |g| dt measure the contact
// solver, not the restitution (docs/comparison.md: ODE reads 0.737 at
// 11 |g| dt on seed-2d-per-contact where its bounce heights give 0.795).
inline constexpr double kMinSpeedInSteps = 30;
double min_measured_impact_speed(const Scenario& s);

// Measured damping against the law's alpha and beta, over the contacts
// before the simulator's rest that hit the wall at min_measured_impact_speed
// or faster.
struct DampingCheck {
    int contacts = 0, tangential_contacts = 0;
    double normal_mean = 0, normal_worst = 0;  // measured coefficient; worst = farthest from alpha
    double tangential_mean = 0, tangential_worst = 0;
    double normal_tolerance = kDefaultDampingTolerance, tangential_tolerance = kDefaultDampingTolerance;
    // The mean tangential loss (1 - retention) against the law's (1 - beta),
    // relative to max(1 - beta, kMinTangentialLossScale).
    double tangential_loss_mean = 0, tangential_loss_rel = 0;
    double tangential_loss_tolerance = kDefaultTangentialLossTolerance;
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
// at min_measured_impact_speed or faster.
std::vector<ContactEvent> damping_contacts(const SimulatorSummary& self, const Scenario& s);

DampingCheck check_damping(const SimulatorSummary& self, const Scenario& s, const ThresholdSet& limits);

// The scenario's thresholds for this simulator, evaluated on its comparison.
std::vector<ThresholdCheck> check_thresholds(const Comparison& c, const ThresholdSet& limits, const Scenario& s);

// The limits that apply to `simulator`: the scenario's [thresholds], its
// [thresholds.<simulator>], then the command line's. The reference is the
// baseline: only a [thresholds.reference] table (or the command line) gates it.
ThresholdSet limits_for(const Scenario& s, const std::string& simulator, const ThresholdSet& overrides);

}  // namespace bouncecheck
