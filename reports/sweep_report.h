// The files and table of a work-precision sweep (`bouncecheck sweep`):
// its rows, each simulator's fitted order, sweep.csv, sweep.json, sweep.html
// and the terminal table.
#pragma once

#include "platform/output_manifest.h"
#include "reports/web_assets.h"
#include "scenarios/scenario.h"
#include "simulators/simulator.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace bouncecheck {

inline constexpr const char* kSweepSchema = "bouncecheck-sweep/1";

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
    std::optional<double> min_seconds;   // the fastest timed run (its engine's steps, where it timed them)
    // Where the simulator timed its own steps: the fastest timed run's wall
    // time outside them (an external's start-up, reading and printing).
    std::optional<double> outside_step_seconds;
};

struct SweepOrder {
    std::string engine;
    std::optional<double> order;  // slope of log(error) against log(dt); needs two points
    int points = 0;               // successful rows with error > 0
};

struct SweepResult {
    std::vector<SweepRow> rows;  // engine-major, in the request's order; dt in the request's order
    // rows[i] is pair slots[i] of the whole run (engine e, dt d: e x dts + d).
    // Every pair unless the run was one shard of it.
    std::vector<std::size_t> slots;
    std::vector<SweepOrder> orders;  // one per engine, in the request's order
};

// For each row: is it on the Pareto front of error against cost (sec_per_sim_sec)?
// A row is, if it succeeded with error > 0 and no other such row is at least
// as good on both and better on one.
std::vector<bool> pareto_front(const std::vector<SweepRow>& rows);

// --no-timings: each row's ns_per_step, sec_per_sim_sec and min_seconds
// left out, so the same input gives the same bytes. Then no row has a cost:
// nothing is on the Pareto front, and sweep.html plots the error against dt.
void leave_out_timings(SweepResult& r);

// sweep.csv: engine,dt,status,error,bounce_error,ns_per_step,sec_per_sim_sec,steps
std::string sweep_csv(const SweepResult& r);
// sweep.json: the rows (with their Pareto flag), each engine's fitted order and the command's parameters.
nlohmann::json sweep_json(const Scenario& s, const SweepResult& r, const nlohmann::json& parameters,
                          const nlohmann::json& provenance = nullptr);
// The terminal table: engine, dt, error, bounce error, ns/step; each engine's order.
std::string format_sweep(const Scenario& s, const SweepResult& r);

// Why an engine's fitted order is not the law's convergence order, if it is
// not: errors at the round-off floor (largest below 1e-9 of the room) have no
// order; an engine in friction mode converges to Coulomb friction, not to the
// law's beta, once the scenario has tangential motion. Empty otherwise.
std::string order_caveat(const SweepOrder& o, const SweepResult& r, const Scenario& s);
// sweep.html: the work-precision plot (log-log error against cost, one line
// per engine, the Pareto front marked) and the orders, self-contained like
// report.html (reports/html_report.cpp).
Page sweep_html(const nlohmann::json& sweep);
// Writes DIR/sweep.csv, DIR/sweep.json and DIR/sweep.html, each atomically;
// returns their names.
WrittenFiles write_sweep(const Scenario& s, const SweepResult& r, const nlohmann::json& parameters,
                         const std::filesystem::path& out_dir, const nlohmann::json& provenance = nullptr);

}  // namespace bouncecheck
