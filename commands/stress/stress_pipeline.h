// `bouncecheck stress`: every simulator on scenarios built to break it (fast
// balls, large steps, extreme sizes, elastic and dead bounces, corners, wall
// starts, no gravity, diagonal gravity, a long horizon, a Monte-Carlo set),
// each run watched for invariants that a sound simulator keeps whatever the
// scenario: a finite state, the ball in the room, no energy gained, a run that
// ends in bounded time, and a cost per step that stays flat.
#pragma once

#include "platform/shard.h"
#include "reports/stress_report.h"
#include "scenarios/scenario.h"
#include "simulators/simulator.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace bouncecheck {

// The tolerance of each invariant for one scenario (see stress_limits).
struct StressLimits {
    double penetration = 0;        // m the ball's surface may reach beyond a wall
    double energy_rise = 0;        // J/kg the energy may rise above its initial value
    double budget_seconds = 0;     // wall time of one run
    double cost_ratio = 0;         // late over early ns/step
};
// Penetration: half the radius (beyond r the centre has left the room).
// Energy (alpha, beta <= 1): 1% of the energy the ball can give up at the
// start (kinetic, plus potential down to the walls gravity points at), plus
// k^2 |g|^2 dt^2, the energy of the micro-bounce a stepped simulator keeps at
// rest (k as in StreamRecorder's rest detection). Cost: late ns/step at most
// kCostRatioLimit times early ns/step.
StressLimits stress_limits(const Scenario& s, double budget_seconds);

inline constexpr double kDefaultBudgetSeconds = 30;

// The watchdog's limit for one run: past it, the run's worker process is
// killed and the run is hung. Later than the budget, which a run that still
// hands states over ends itself (the time_budget invariant): the watchdog is
// for a run stuck inside one step, or an engine that never returns.
double stress_deadline_seconds(double budget_seconds);

struct StressRequest {
    std::vector<const Simulator*> simulators;
    int jobs = 0;  // worker processes; 0: every core
    double budget_seconds = kDefaultBudgetSeconds;
    Shard shard;  // --shard: only this part of the pairs (platform/shard.h)
    // Called in this process as each run ends, in the order they end.
    std::function<void(const StressResult&, std::size_t done, std::size_t total)> on_progress;
};

// Runs `s` on `sim` and judges every invariant.
StressResult run_stress_case(const StressCase& c, const Simulator& sim, double budget_seconds);

// Every (case, simulator) pair (of the request's shard), in parallel in
// worker processes (run_pairs_in_parallel): a run that crashes or hangs its
// process is that run's result only.
StressReport run_stress(const std::vector<StressCase>& cases, const StressRequest& request);

// A result as bytes that keep every double's bits (commands/wire.h), for a
// worker's channel and a shard's file, and back. Row, scenario and simulator
// are not in the bytes: the reader knows them from the pair.
std::string encode_stress_result(const StressResult& r);
void decode_stress_result(const std::string& bytes, StressResult& r);
// The report of the whole run from every pair's bytes, in slot order (every
// slot once; merge checks that): the same report, bit for bit, that the
// unsharded run makes, apart from wall_seconds, which is the caller's.
StressReport stress_report_from_results(const std::vector<StressCase>& cases,
                                        const std::vector<std::string>& simulators, double budget_seconds,
                                        const std::vector<std::string>& results);

}  // namespace bouncecheck
