// A work-precision sweep (`bouncecheck sweep`): each simulator at a series of
// time steps, its error against exact and its cost per step, and the observed
// convergence order fitted over the series.
#pragma once

#include "platform/shard.h"
#include "reports/sweep_report.h"
#include "scenarios/scenario.h"
#include "simulators/simulator.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

inline constexpr double kSweepMinDt = 1e-5;  // the default series stops here...
inline constexpr int kSweepMaxHalvings = 7;  // ...or after this many halvings of the scenario's dt
inline constexpr std::size_t kSweepMaxDts = 1000;

// The default series: dt, dt/2, dt/4, ... while >= max(1e-5, dt / 2^7).
// Always holds dt itself.
std::vector<double> default_sweep_dts(double dt);

// --dt: either a comma-separated list (0.03,0.015,...) or FROM:TO:FACTOR,
// meaning FROM, FROM/FACTOR, FROM/FACTOR^2, ... while >= TO (with a relative
// slack of 1e-9 for the rounding of the divisions). Every dt must be finite
// and > 0; FACTOR > 1; FROM >= TO > 0.
struct DtParse {
    std::vector<double> dts;
    std::string error;  // empty on success
};
DtParse parse_dt_list(std::string_view text);

struct SweepRequest {
    std::vector<const Simulator*> simulators;
    std::vector<double> dts;
    int repeat = 3;  // timed runs per pair (the minimum is kept)
    int jobs = 0;    // worker processes; 0: every core
    // Wall-time limit of one pair, its timed repeats included (s): past it the
    // pair's worker process is killed and the row fails as hung. 0: no limit.
    double budget_seconds = 0;
    Shard shard;  // --shard: only this part of the pairs (platform/shard.h)
    // Called in this process as each pair ends, in the order they end.
    std::function<void(const SweepRow& row, std::size_t done, std::size_t total)> on_progress;
};

// Runs every (simulator, dt) pair, in parallel in worker processes
// (run_pairs_in_parallel), a crash or a hang costing its own row only. Every
// pair's result has its own slot, so the rows do not depend on `jobs` (only
// the timings do). A simulator that cannot run the scenario, or fails, is a
// row with its status and reason.
SweepResult run_sweep(const Scenario& s, const SweepRequest& request);

// A row as bytes that keep every double's bits (commands/wire.h), for a
// worker's channel and a shard's file, and back. Engine and dt are not in the
// bytes: the reader knows them from the pair.
std::string encode_sweep_row(const SweepRow& r);
void decode_sweep_row(const std::string& bytes, SweepRow& r);
// The whole sweep from every pair's bytes, in slot order (every slot once;
// merge checks that), with the orders fitted: the same result, bit for bit,
// that the unsharded sweep makes.
SweepResult sweep_result_from_rows(const std::vector<std::string>& simulators, const std::vector<double>& dts,
                                   const std::vector<std::string>& rows);

// Least-squares slope of log(error) against log(dt) over `engine`'s ok rows with error > 0.
SweepOrder fit_order(const std::vector<SweepRow>& rows, const std::string& engine);

}  // namespace bouncecheck
