#include "commands/sweep/sweep_pipeline.h"

#include "commands/run/run_pipeline.h"
#include "commands/wire.h"
#include "platform/parallel_pairs.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>
#include <utility>

namespace bouncecheck {

std::vector<double> default_sweep_dts(double dt) {
    const double floor = std::max(kSweepMinDt, std::ldexp(dt, -kSweepMaxHalvings));
    std::vector<double> dts{dt};
    for (double next = dt / 2; next >= floor && dts.size() < kSweepMaxDts; next /= 2) dts.push_back(next);
    return dts;
}

namespace {

// A whole string as a finite double (spaces around it allowed, as in every list), or nothing.
std::optional<double> parse_number(std::string_view text) {
    while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
    while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
    const std::string s(text);
    if (s.empty() || std::isspace(static_cast<unsigned char>(s.front()))) return std::nullopt;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) return std::nullopt;
    return v;
}

}  // namespace

DtParse parse_dt_list(std::string_view text) {
    DtParse out;
    auto fail = [&](std::string message) {
        out.dts.clear();
        out.error = std::move(message);
        return out;
    };
    if (text.empty()) return fail("empty; expected a list 0.03,0.015,... or FROM:TO:FACTOR");
    if (text.find(':') != std::string_view::npos) {
        std::vector<std::string_view> parts;
        for (std::size_t start = 0;;) {
            const auto colon = text.find(':', start);
            parts.push_back(text.substr(start, colon == std::string_view::npos ? colon : colon - start));
            if (colon == std::string_view::npos) break;
            start = colon + 1;
        }
        if (parts.size() != 3) return fail(fmt::format("'{}': expected FROM:TO:FACTOR", text));
        const auto from = parse_number(parts[0]), to = parse_number(parts[1]), factor = parse_number(parts[2]);
        if (!from || !to || !factor) return fail(fmt::format("'{}': FROM, TO and FACTOR must be finite numbers", text));
        if (*to <= 0) return fail(fmt::format("'{}': TO must be > 0", text));
        if (*from < *to) return fail(fmt::format("'{}': FROM must be >= TO", text));
        if (*factor <= 1) return fail(fmt::format("'{}': FACTOR must be > 1", text));
        const double last = *to * (1 - 1e-9);  // slack for the rounding of repeated division
        for (double dt = *from; dt >= last; dt /= *factor) {
            if (out.dts.size() == kSweepMaxDts)
                return fail(fmt::format("'{}': more than {} time steps", text, kSweepMaxDts));
            out.dts.push_back(dt);
        }
        return out;
    }
    for (std::size_t start = 0;;) {
        const auto comma = text.find(',', start);
        const auto item = text.substr(start, comma == std::string_view::npos ? comma : comma - start);
        const auto dt = parse_number(item);
        if (!dt) return fail(fmt::format("'{}' is not a number", item));
        if (*dt <= 0) return fail(fmt::format("'{}': a time step must be > 0", item));
        if (out.dts.size() == kSweepMaxDts) return fail(fmt::format("more than {} time steps", kSweepMaxDts));
        out.dts.push_back(*dt);
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return out;
}


namespace {

SweepRow failed_row(const std::string& engine, double dt, std::string reason) {
    SweepRow row;
    row.engine = engine;
    row.dt = dt;
    row.status = RunStatus::failed;
    row.reason = std::move(reason);
    return row;
}

SweepRow run_pair(const Scenario& base, const Simulator& sim, double dt, int repeat) {
    SweepRow row;
    row.engine = std::string(sim.name());
    row.dt = dt;
    Scenario s = base;
    s.dt = dt;
    try {
        if (auto why = sim.cannot_run(s)) {
            row.status = RunStatus::skipped;
            row.reason = *why;
            return row;
        }
        const ScenarioRun run = run_scenario(s, RunRequest{{&sim}, {}, false, {}});
        const SimulatorSummary& result = run.results.front();
        row.status = result.status;
        row.reason = result.reason;
        if (result.status != RunStatus::ok) {
            if (result.steps > 0) row.steps = result.steps;
            return row;
        }
        const Comparison& c = *run.comparisons.front();
        row.error = c.vs_exact.trajectory.rms_before_rest;
        row.bounce_error = c.vs_exact.bounce_height_rel_max;
        row.steps = result.steps;

        double best = std::numeric_limits<double>::infinity();
        for (int i = 0; i < repeat; ++i) {
            const UnrecordedRun timed = sim.run_unrecorded(s);
            if (timed.status != RunStatus::ok) {
                row.status = timed.status;
                row.reason = fmt::format("timed run {}: {}", i + 1, timed.reason);
                row.error.reset();
                row.bounce_error.reset();
                return row;
            }
            // An engine that timed its own steps is charged for them only;
            // the rest of its run (an external's start-up) is reported apart.
            const double engine_seconds = timed.step_seconds.value_or(timed.run_seconds);
            if (engine_seconds < best) {
                best = engine_seconds;
                if (timed.step_seconds) row.outside_step_seconds = timed.run_seconds - *timed.step_seconds;
            }
        }
        row.min_seconds = best;
        if (result.steps > 0) row.ns_per_step = best * 1e9 / static_cast<double>(result.steps);
        row.sec_per_sim_sec = best / s.duration;
    } catch (const std::exception& e) {
        return failed_row(row.engine, dt, fmt::format("exception: {}", e.what()));
    } catch (...) {
        return failed_row(row.engine, dt, "unknown exception");
    }
    return row;
}

}  // namespace

SweepOrder fit_order(const std::vector<SweepRow>& rows, const std::string& engine) {
    SweepOrder o;
    o.engine = engine;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const SweepRow& r : rows) {
        if (r.engine != engine || r.status != RunStatus::ok || !r.error || !(*r.error > 0)) continue;
        const double x = std::log(r.dt), y = std::log(*r.error);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        ++o.points;
    }
    if (o.points >= 2) {
        const double n = o.points;
        const double denominator = n * sxx - sx * sx;
        if (denominator > 0) o.order = (n * sxy - sx * sy) / denominator;
    }
    return o;
}

// ------------------------------------------------ a row across a worker's channel (commands/wire.h)

std::string encode_sweep_row(const SweepRow& r) {
    using wire::optional;
    return wire::to_bytes({static_cast<int>(r.status), r.reason, optional(r.error), optional(r.bounce_error),
                           optional(r.ns_per_step), optional(r.sec_per_sim_sec), optional(r.steps),
                           optional(r.min_seconds), optional(r.outside_step_seconds)});
}

void decode_sweep_row(const std::string& bytes, SweepRow& r) {
    const nlohmann::json j = wire::from_bytes(bytes);
    r.status = static_cast<RunStatus>(j[0].get<int>());
    r.reason = j[1].get<std::string>();
    r.error = wire::optional_from<double>(j[2]);
    r.bounce_error = wire::optional_from<double>(j[3]);
    r.ns_per_step = wire::optional_from<double>(j[4]);
    r.sec_per_sim_sec = wire::optional_from<double>(j[5]);
    r.steps = wire::optional_from<std::int64_t>(j[6]);
    r.min_seconds = wire::optional_from<double>(j[7]);
    r.outside_step_seconds = wire::optional_from<double>(j[8]);
}

namespace {

// The sweep's frame: every pair's slot with its engine and dt.
SweepResult empty_result(const std::vector<std::string>& simulators, const std::vector<double>& dts) {
    SweepResult result;
    for (const std::string& engine : simulators)
        for (double dt : dts) {
            SweepRow row;
            row.engine = engine;
            row.dt = dt;
            result.slots.push_back(result.rows.size());
            result.rows.push_back(std::move(row));
        }
    return result;
}

void fit_orders(const std::vector<std::string>& simulators, SweepResult& result) {
    for (const std::string& engine : simulators) result.orders.push_back(fit_order(result.rows, engine));
}

}  // namespace

SweepResult run_sweep(const Scenario& s, const SweepRequest& request) {
    std::vector<std::string> names;
    for (const Simulator* sim : request.simulators) names.emplace_back(sim->name());
    SweepResult result = empty_result(names, request.dts);
    const std::size_t n_dt = request.dts.size();
    std::vector<bool> ran(result.rows.size(), false);

    const int repeat = std::max(1, request.repeat);
    PairSchedule schedule;
    schedule.jobs = request.jobs;
    schedule.shard = request.shard;
    schedule.deadline_seconds = request.budget_seconds;
    schedule.cost = [&](std::size_t e, std::size_t d) {
        return s.duration / request.dts[d] * request.simulators[e]->typical_ns_per_step();
    };
    schedule.run = [&](std::size_t e, std::size_t d) {
        return encode_sweep_row(run_pair(s, *request.simulators[e], request.dts[d], repeat));
    };
    schedule.finished = [&](std::size_t e, std::size_t d, const PairOutcome& o, std::size_t done, std::size_t total) {
        SweepRow& row = result.rows[e * n_dt + d];
        ran[e * n_dt + d] = true;
        if (const auto failure = decode_pair(o, [&](const std::string& payload) { decode_sweep_row(payload, row); }))
            row = failed_row(row.engine, row.dt, failure->labelled());
        if (request.on_progress) request.on_progress(row, done, total);
    };
    run_pairs_in_parallel(request.simulators.size(), n_dt, schedule);
    if (!request.shard.whole()) keep_pairs_that_ran(ran, result.rows, result.slots);
    fit_orders(names, result);
    return result;
}

SweepResult sweep_result_from_rows(const std::vector<std::string>& simulators, const std::vector<double>& dts,
                                   const std::vector<std::string>& rows) {
    SweepResult result = empty_result(simulators, dts);
    if (rows.size() != result.rows.size())
        throw std::runtime_error(fmt::format("{} rows for a sweep of {} pairs", rows.size(), result.rows.size()));
    for (std::size_t slot = 0; slot < rows.size(); ++slot) decode_sweep_row(rows[slot], result.rows[slot]);
    fit_orders(simulators, result);
    return result;
}

}  // namespace bouncecheck
