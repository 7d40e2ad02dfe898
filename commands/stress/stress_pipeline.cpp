#include "commands/stress/stress_pipeline.h"

#include "commands/wire.h"
#include "metrics/summary.h"
#include "platform/parallel_pairs.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace bouncecheck {

StressLimits stress_limits(const Scenario& s, double budget_seconds) {
    StressLimits l;
    l.penetration = 0.5 * s.radius;
    double available = 0.5 * s.velocity.squaredNorm();
    for (int i = 0; i < s.dim; ++i) {
        const double g = s.gravity[i];
        available += std::abs(g) * (g < 0 ? s.position[i] - s.radius : s.room[i] - s.radius - s.position[i]);
    }
    const double k = s.alpha < 1 ? std::clamp((1 + s.alpha) / (1 - s.alpha), 2.0, 20.0) : 20.0;
    const double g = s.gravity.norm();
    // The last term is round-off: a float engine's energy is good to ~1e-7 of its terms.
    const double scale = 0.5 * s.velocity.squaredNorm() + g * s.room.head(s.dim).maxCoeff();
    l.energy_rise = 0.01 * available + k * k * g * g * s.dt * s.dt + 1e-6 * scale;
    l.budget_seconds = budget_seconds;
    l.cost_ratio = kCostRatioLimit;
    return l;
}

namespace {

// Thrown from the watch when a run overstays its budget: unwinds the
// simulator's run (every adapter owns its world through RAII). Not a
// std::exception, so nothing on the way catches it as a simulator error.
struct BudgetExceeded {
    double t;
};

// Watches a run's states for the first one beyond each tolerance, and times
// blocks of states for the cost check. The worst values come from the
// summary's StreamRecorder measures, when the run completes.
class InvariantWatch final : public StateSink {
public:
    InvariantWatch(const Scenario& s, const StressLimits& limits) : s_(s), walls_(s), limits_(limits) {}

    void write(const State& st) override {
        using clock = std::chrono::steady_clock;
        const double energy = specific_energy(st, s_.gravity);
        if (states_ == 0) {
            energy0_ = energy;
            start_ = block_start_ = clock::now();
            block_t_ = st.t;
        }
        bool finite = std::isfinite(st.t);
        for (int i = 0; i < s_.dim; ++i) finite = finite && std::isfinite(st.p[i]) && std::isfinite(st.v[i]);
        if (!finite && !non_finite_t_) non_finite_t_ = st.t;
        const double penetration = walls_.penetration(st.p);
        note(st.t, penetration, limits_.penetration, penetration_);
        note(st.t, energy - energy0_, limits_.energy_rise, energy_);
        ++states_;
        if (states_ % kCostBlockSteps == 0) {
            const auto now = clock::now();
            blocks_.push_back({block_t_, std::chrono::duration<double>(now - block_start_).count() * 1e9 /
                                             static_cast<double>(kCostBlockSteps)});
            block_start_ = now;
            block_t_ = st.t;
            if (std::chrono::duration<double>(now - start_).count() > limits_.budget_seconds) throw BudgetExceeded{st.t};
        }
    }

    struct Crossing {
        double worst = -std::numeric_limits<double>::infinity();
        std::optional<double> t;
        double value = 0;
    };
    struct Block {
        double t;   // simulated time at the block's start
        double ns;  // per step
    };

    std::int64_t states() const { return states_; }
    std::optional<double> non_finite_t() const { return non_finite_t_; }
    const Crossing& penetration() const { return penetration_; }
    const Crossing& energy() const { return energy_; }
    const std::vector<Block>& blocks() const { return blocks_; }

private:
    static void note(double t, double value, double tolerance, Crossing& c) {
        if (value > c.worst) c.worst = value;
        if (!c.t && value > tolerance) {
            c.t = t;
            c.value = value;
        }
    }

    const Scenario& s_;
    WallLimits walls_;
    StressLimits limits_;
    std::int64_t states_ = 0;
    double energy0_ = 0;
    std::optional<double> non_finite_t_;
    Crossing penetration_, energy_;
    std::chrono::steady_clock::time_point start_, block_start_;
    double block_t_ = 0;
    std::vector<Block> blocks_;

};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Early and late cost: the median ns/step of the first and of the last quarter of blocks.
InvariantCheck cost_check(const std::vector<InvariantWatch::Block>& blocks, double limit) {
    InvariantCheck c{Invariant::flat_cost, false, true, limit, 0, std::nullopt, 0};
    if (blocks.size() < static_cast<std::size_t>(kCostMinBlocks)) return c;
    const std::size_t quarter = blocks.size() / 4;
    std::vector<double> early, late;
    for (std::size_t i = 0; i < quarter; ++i) early.push_back(blocks[i].ns);
    for (std::size_t i = blocks.size() - quarter; i < blocks.size(); ++i) late.push_back(blocks[i].ns);
    const double base = median(early);
    c.checked = base > 0;
    if (!c.checked) return c;
    c.worst = median(late) / base;
    c.held = c.worst <= limit;
    if (!c.held) {
        for (std::size_t i = quarter; i < blocks.size(); ++i) {
            if (blocks[i].ns > limit * base) {
                c.first_t = blocks[i].t;
                c.first_value = blocks[i].ns / base;
                break;
            }
        }
    }
    return c;
}

std::string setting_value(const SimulatorSummary& s, const std::string& key) {
    for (const auto& setting : s.settings)
        if (setting.key == key) return setting.value;
    return "";
}

}  // namespace

StressResult run_stress_case(const StressCase& c, const Simulator& sim, double budget_seconds) {
    const Scenario& s = c.scenario;
    StressResult r;
    r.row = c.row;
    r.scenario = s.name;
    r.simulator = std::string(sim.name());
    if (auto why = sim.cannot_run(s)) {
        r.outcome = StressOutcome::skipped;
        r.reason = *why;
        return r;
    }
    const StressLimits limits = stress_limits(s, budget_seconds);
    InvariantWatch watch(s, limits);
    std::optional<SimulatorSummary> summary;
    std::optional<double> aborted_at;
    const double seconds = timed_seconds([&] {
        try {
            summary = record_run(sim, s, &watch);
        } catch (const BudgetExceeded& b) {
            aborted_at = b.t;
        } catch (const std::exception& e) {
            r.outcome = StressOutcome::crashed;
            r.reason = fmt::format("exception: {}", e.what());
        } catch (...) {
            r.outcome = StressOutcome::crashed;
            r.reason = "unknown exception";
        }
    });
    r.run_seconds = summary ? summary->run_seconds : seconds;
    r.steps = summary ? summary->steps : std::max<std::int64_t>(0, watch.states() - 1);
    if (summary) {
        r.ccd = setting_value(*summary, "ccd");
        r.substeps = setting_value(*summary, "substeps");
    }
    if (r.outcome == StressOutcome::crashed) return r;

    InvariantCheck finite{Invariant::finite, true, !watch.non_finite_t(), 0, watch.non_finite_t() ? 1.0 : 0.0,
                          watch.non_finite_t(), 0};
    InvariantCheck room{Invariant::in_room, true, !watch.penetration().t, limits.penetration,
                        summary ? summary->max_penetration : watch.penetration().worst, watch.penetration().t,
                        watch.penetration().value};
    const bool dissipative = s.alpha <= 1 && s.beta <= 1;
    InvariantCheck energy{Invariant::energy, dissipative, !dissipative || !watch.energy().t, limits.energy_rise,
                          summary ? summary->energy_max_rise : std::max(0.0, watch.energy().worst),
                          dissipative ? watch.energy().t : std::nullopt, watch.energy().value};
    InvariantCheck budget{Invariant::time_budget, true, !aborted_at && seconds <= budget_seconds, budget_seconds,
                          seconds, aborted_at, seconds};
    if (!budget.held && !budget.first_t) budget.first_t = summary ? summary->final_state.t : 0.0;
    r.checks = {finite, room, energy, budget, cost_check(watch.blocks(), limits.cost_ratio)};

    // The recorder fails a run for a non-finite state or a ball beyond a wall,
    // which the watch sees too; any other failure is the simulator giving up
    // (exact's event cap): its later states are no finding, the run is a hole.
    if (summary && summary->status == RunStatus::failed && finite.held && room.held) {
        r.outcome = StressOutcome::crashed;
        r.reason = summary->reason;
    } else if (const InvariantCheck* first = r.first_broken()) {
        r.outcome = StressOutcome::fail;
        r.reason = fmt::format("{} broke at t = {:.6g} s", to_string(first->invariant), first->first_t.value_or(0.0));
    }
    return r;
}

// ------------------------------------------------ a result across a worker's channel (commands/wire.h)

std::string encode_stress_result(const StressResult& r) {
    using nlohmann::json;
    json checks = json::array();
    for (const InvariantCheck& c : r.checks)
        checks.push_back({static_cast<int>(c.invariant), c.checked, c.held, c.tolerance, c.worst,
                          wire::optional(c.first_t), c.first_value});
    return wire::to_bytes({static_cast<int>(r.outcome), r.reason, checks, r.steps, r.run_seconds, r.ccd, r.substeps});
}

void decode_stress_result(const std::string& bytes, StressResult& r) {
    const nlohmann::json j = wire::from_bytes(bytes);
    r.outcome = static_cast<StressOutcome>(j[0].get<int>());
    r.reason = j[1].get<std::string>();
    for (const nlohmann::json& c : j[2])
        r.checks.push_back(InvariantCheck{static_cast<Invariant>(c[0].get<int>()), c[1].get<bool>(), c[2].get<bool>(),
                                          c[3].get<double>(), c[4].get<double>(), wire::optional_from<double>(c[5]),
                                          c[6].get<double>()});
    r.steps = j[3].get<std::int64_t>();
    r.run_seconds = j[4].get<double>();
    r.ccd = j[5].get<std::string>();
    r.substeps = j[6].get<std::string>();
}

namespace {

// The report's frame: rows in suite order, every pair's slot with its names.
StressReport empty_report(const std::vector<StressCase>& cases, const std::vector<std::string>& simulators,
                          double budget_seconds) {
    StressReport report;
    report.budget_seconds = budget_seconds;
    for (const StressCase& c : cases)
        if (std::find(report.rows.begin(), report.rows.end(), c.row) == report.rows.end()) report.rows.push_back(c.row);
    report.simulators = simulators;
    report.results.resize(cases.size() * simulators.size());
    for (std::size_t slot = 0; slot < report.results.size(); ++slot) {
        StressResult& r = report.results[slot];
        const StressCase& c = cases[slot / simulators.size()];
        r.row = c.row;
        r.scenario = c.scenario.name;
        r.simulator = simulators[slot % simulators.size()];
        report.slots.push_back(slot);
    }
    return report;
}

}  // namespace

double stress_deadline_seconds(double budget_seconds) { return 1.5 * budget_seconds + 1; }

StressReport run_stress(const std::vector<StressCase>& cases, const StressRequest& request) {
    const auto wall_start = std::chrono::steady_clock::now();
    std::vector<std::string> names;
    for (const Simulator* sim : request.simulators) names.emplace_back(sim->name());
    StressReport report = empty_report(cases, names, request.budget_seconds);
    const std::size_t n_sim = request.simulators.size();
    std::vector<bool> ran(report.results.size(), false);

    PairSchedule schedule;
    schedule.jobs = request.jobs;
    schedule.shard = request.shard;
    schedule.deadline_seconds = stress_deadline_seconds(request.budget_seconds);
    schedule.cost = [&](std::size_t e, std::size_t c) {
        const Scenario& s = cases[c].scenario;
        const double ns = s.duration / s.dt * request.simulators[e]->typical_ns_per_step();
        return std::min(ns, request.budget_seconds * 1e9);  // a run ends at its budget
    };
    schedule.run = [&](std::size_t e, std::size_t c) {
        return encode_stress_result(run_stress_case(cases[c], *request.simulators[e], request.budget_seconds));
    };
    schedule.finished = [&](std::size_t e, std::size_t c, const PairOutcome& o, std::size_t done, std::size_t total) {
        StressResult& r = report.results[c * n_sim + e];
        ran[c * n_sim + e] = true;
        const auto decode = [&](const std::string& payload) { decode_stress_result(payload, r); };
        if (const auto failure = decode_pair(o, decode)) {
            r.outcome = failure->kind == PairFailure::Kind::hung ? StressOutcome::hung : StressOutcome::crashed;
            r.reason = failure->reason;
        }
        if (request.on_progress) request.on_progress(r, done, total);
    };
    run_pairs_in_parallel(request.simulators.size(), cases.size(), schedule);
    if (!request.shard.whole()) keep_pairs_that_ran(ran, report.results, report.slots);
    report.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    return report;
}

StressReport stress_report_from_results(const std::vector<StressCase>& cases,
                                        const std::vector<std::string>& simulators, double budget_seconds,
                                        const std::vector<std::string>& results) {
    StressReport report = empty_report(cases, simulators, budget_seconds);
    if (results.size() != report.results.size())
        throw std::runtime_error(fmt::format("{} results for a run of {} pairs", results.size(), report.results.size()));
    for (std::size_t slot = 0; slot < results.size(); ++slot) decode_stress_result(results[slot], report.results[slot]);
    return report;
}

}  // namespace bouncecheck
