// A work-precision sweep (`bouncecheck sweep`): each simulator at a series of
// time steps, its error against exact and its cost per step, and the observed
// convergence order fitted over the series.
#pragma once

#include "simulators/simulator.h"
#include "platform/parallel_pairs.h"
#include "metrics/summary.h"
#include "scenarios/scenario.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

inline constexpr const char* kSweepSchema = "bouncecheck-sweep/1";
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

struct SweepRow {
    std::string engine;
    double dt = 0;
    RunStatus status = RunStatus::ok;
    std::string reason;                  // why skipped or failed
    std::optional<double> error;         // trajectory RMS against exact before exact's rest (m)
    std::optional<double> bounce_error;  // largest relative bounce height difference against exact
    std::optional<double> ns_per_step;   // min over the timed runs
    std::optional<double> sec_per_sim_sec;
    std::optional<std::int64_t> steps;
    std::optional<double> min_seconds;   // the fastest timed run
};

struct SweepOrder {
    std::string engine;
    std::optional<double> order;  // slope of log(error) against log(dt); needs two points
    int points = 0;               // successful rows with error > 0
};

struct SweepResult {
    std::vector<SweepRow> rows;  // engine-major, in the request's order; dt in the request's order
    std::vector<SweepOrder> orders;  // one per engine, in the request's order
};

struct SweepRequest {
    std::vector<const Simulator*> simulators;
    std::vector<double> dts;
    int repeat = 3;  // timed runs per pair (the minimum is kept)
    int jobs = 0;    // worker threads; 0: every core
    // Called (under a lock, from a worker thread) as each pair finishes.
    std::function<void(const SweepRow& row, std::size_t done, std::size_t total)> on_progress;
};

// Runs every (simulator, dt) pair, in parallel over pairs (oneTBB). Every
// pair's result has its own slot, so the rows do not depend on `jobs` (only
// the timings do). A simulator that cannot run the scenario, or fails, is a
// row with its status and reason.
SweepResult run_sweep(const Scenario& s, const SweepRequest& request);

// Least-squares slope of log(error) against log(dt) over `engine`'s ok rows with error > 0.
SweepOrder fit_order(const std::vector<SweepRow>& rows, const std::string& engine);

// For each row: is it on the Pareto front of error against cost (sec_per_sim_sec)?
// A row is, if it succeeded with error > 0 and no other such row is at least
// as good on both and better on one.
std::vector<bool> pareto_front(const std::vector<SweepRow>& rows);

// sweep.csv: engine,dt,status,error,bounce_error,ns_per_step,sec_per_sim_sec,steps
std::string sweep_csv(const SweepResult& r);
// sweep.json: the rows (with their Pareto flag), each engine's fitted order and the command's parameters.
nlohmann::json sweep_json(const Scenario& s, const SweepResult& r, const nlohmann::json& parameters);
// The terminal table: engine, dt, error, bounce error, ns/step; each engine's order.
std::string format_sweep(const Scenario& s, const SweepResult& r);
// sweep.html: the work-precision plot (log-log error against cost, one line
// per engine, the Pareto front marked) and the orders, self-contained like
// report.html (compare/html_report.cpp).
std::string sweep_html(const nlohmann::json& sweep);
// Writes DIR/sweep.csv, DIR/sweep.json and DIR/sweep.html, each atomically.
void write_sweep(const Scenario& s, const SweepResult& r, const nlohmann::json& parameters,
                 const std::filesystem::path& out_dir);

}  // namespace bouncecheck
