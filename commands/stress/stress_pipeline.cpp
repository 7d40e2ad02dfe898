#include "commands/stress/stress_pipeline.h"

#include "platform/atomic_file.h"
#include "reports/json_number.h"
#include "metrics/summary.h"
#include "platform/parallel_pairs.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <set>
#include <utility>

namespace bouncecheck {

// --- the generated families ---

double unit_draw(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1p-53; }

namespace {

double uniform(std::mt19937_64& g, double lo, double hi) { return lo + (hi - lo) * unit_draw(g); }
// One of n outcomes; the modulo bias (n / 2^64) is far below anything measurable.
std::uint64_t pick(std::mt19937_64& g, std::uint64_t n) { return g() % n; }
bool one_in(std::mt19937_64& g, std::uint64_t n) { return pick(g, n) == 0; }

}  // namespace

std::vector<Scenario> monte_carlo_scenarios(std::uint64_t seed, int count) {
    std::mt19937_64 g(seed);
    std::vector<Scenario> out;
    for (int n = 0; n < count; ++n) {
        Scenario s;
        s.name = fmt::format("{}-{:04d}", kMonteCarloRow, n);
        s.description = fmt::format("Monte-Carlo scenario {} of seed {}", n, seed);
        s.dim = 2 + static_cast<int>(pick(g, 2));
        s.room = s.position = s.velocity = s.gravity = Vec3::Zero();
        for (int i = 0; i < s.dim; ++i) s.room[i] = uniform(g, 0.2, 3.0);
        s.radius = s.room.head(s.dim).minCoeff() * uniform(g, 0.005, 0.2);
        const double r = s.radius;
        const bool no_gravity = one_in(g, 10);
        for (int i = 0; i < s.dim; ++i) {
            const double high = s.room[i] - r;
            // A start touching a wall, one axis in eight; the clamp keeps a
            // rounded r + (high - r) u within [r, high], as the loader requires.
            switch (pick(g, 16)) {
                case 0: s.position[i] = r; break;
                case 1: s.position[i] = high; break;
                default: s.position[i] = std::min(high, std::max(r, uniform(g, r, high)));
            }
            s.velocity[i] = one_in(g, 8) ? 0.0 : uniform(g, -2.0, 2.0);
            const bool vertical = i == s.dim - 1;
            if (!no_gravity) s.gravity[i] = vertical ? -uniform(g, 0.0, 10.0) : (one_in(g, 4) ? uniform(g, -1.0, 1.0) : 0.0);
        }
        auto factor = [&](double lo) {
            switch (pick(g, 8)) {
                case 0: return 0.0;
                case 1: return 1.0;
                default: return uniform(g, lo, 1.0);
            }
        };
        s.alpha = factor(0.0);
        s.beta = factor(0.5);
        // dt = m 2^-e, m in [1, 2): log-uniform-like without a libm call.
        s.dt = std::ldexp(uniform(g, 1.0, 2.0), -static_cast<int>(5 + pick(g, 8)));
        s.duration = s.dt * static_cast<double>(200 + pick(g, 1801));
        out.push_back(std::move(s));
    }
    return out;
}

std::vector<Scenario> wall_start_scenarios() {
    static constexpr std::array<const char*, 3> kAxis{"x", "y", "z"};
    std::vector<Scenario> out;
    for (const int dim : {2, 3}) {
        for (int axis = 0; axis < dim; ++axis) {
            for (const int side : {-1, +1}) {
                for (const char* motion : {"in", "out", "rest"}) {
                    Scenario s;
                    s.dim = dim;
                    s.room = s.velocity = s.gravity = Vec3::Zero();
                    s.position = Vec3::Zero();
                    for (int i = 0; i < dim; ++i) {
                        s.room[i] = 1.0;
                        s.position[i] = 0.5;
                    }
                    s.radius = 0.05;
                    s.gravity[dim - 1] = -0.0981;
                    s.position[axis] = side < 0 ? s.radius : 1.0 - s.radius;
                    const double into = std::string_view(motion) == "in" ? 0.3 : std::string_view(motion) == "out" ? -0.3 : 0.0;
                    s.velocity[axis] = side * into;
                    // Some motion along the wall too, so that beta has something to damp.
                    if (into != 0.0) s.velocity[(axis + 1) % dim] = 0.1;
                    s.alpha = 0.8;
                    s.beta = 0.99;
                    s.dt = 0.03;
                    s.duration = 10.0;
                    s.name = fmt::format("wall-start-{}d-{}-{}-{}", dim, kAxis[static_cast<std::size_t>(axis)],
                                         side < 0 ? "lower" : "upper", motion);
                    s.description = fmt::format("starts touching the {} {} wall, {}", side < 0 ? "lower" : "upper",
                                                kAxis[static_cast<std::size_t>(axis)],
                                                into > 0 ? "moving into it" : into < 0 ? "moving away" : "at rest");
                    out.push_back(std::move(s));
                }
            }
        }
    }
    return out;
}

std::vector<StressCase> stress_suite(const std::vector<Scenario>& files) {
    std::vector<StressCase> cases;
    for (const Scenario& s : files) cases.push_back({s.name, s, false});
    for (Scenario& s : wall_start_scenarios()) cases.push_back({kWallStartsRow, std::move(s), true});
    for (Scenario& s : monte_carlo_scenarios(kMonteCarloSeed, kMonteCarloCount))
        cases.push_back({kMonteCarloRow, std::move(s), true});
    return cases;
}

std::string scenario_toml(const Scenario& s) {
    auto vec = [&](const Vec3& v) {
        std::string out = "[";
        for (int i = 0; i < s.dim; ++i) out += fmt::format("{}{:.17g}", i ? ", " : "", v[i]);
        return out + "]";
    };
    return fmt::format(
        "name = \"{}\"\ndescription = \"{}\"\n\n[room]\nsize = {}\n\n[ball]\nradius = {:.17g}\nposition = {}\n"
        "velocity = {}\n\n[world]\ngravity = {}\n\n[damping]\nnormal = {:.17g}\ntangential = {:.17g}\n\n"
        "[run]\ndt = {:.17g}\nduration = {:.17g}\n",
        s.name, s.description, vec(s.room), s.radius, vec(s.position), vec(s.velocity), vec(s.gravity), s.alpha,
        s.beta, s.dt, s.duration);
}

// --- invariants ---

const char* to_string(Invariant i) {
    switch (i) {
        case Invariant::finite: return "finite";
        case Invariant::in_room: return "in_room";
        case Invariant::energy: return "energy";
        case Invariant::time_budget: return "time_budget";
        case Invariant::flat_cost: return "flat_cost";
    }
    return "?";
}

const char* to_string(StressOutcome o) {
    switch (o) {
        case StressOutcome::pass: return "pass";
        case StressOutcome::fail: return "fail";
        case StressOutcome::skipped: return "skipped";
        case StressOutcome::crashed: return "crashed";
    }
    return "?";
}

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

const InvariantCheck* StressResult::first_broken() const {
    const InvariantCheck* first = nullptr;
    for (const InvariantCheck& c : checks) {
        if (c.held) continue;
        if (!first || (c.first_t && (!first->first_t || *c.first_t < *first->first_t))) first = &c;
    }
    return first;
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

StressReport run_stress(const std::vector<StressCase>& cases, const StressRequest& request) {
    const auto wall_start = std::chrono::steady_clock::now();
    StressReport report;
    report.budget_seconds = request.budget_seconds;
    for (const StressCase& c : cases)
        if (std::find(report.rows.begin(), report.rows.end(), c.row) == report.rows.end()) report.rows.push_back(c.row);
    for (const Simulator* sim : request.simulators) report.simulators.emplace_back(sim->name());
    const std::size_t n_sim = request.simulators.size();
    const std::size_t total = cases.size() * n_sim;
    report.results.resize(total);

    PairSchedule schedule;
    schedule.jobs = request.jobs;
    schedule.serial = [&](std::size_t e) { return request.simulators[e]->serial_reason().has_value(); };
    schedule.cost = [&](std::size_t c) { return cases[c].scenario.duration / cases[c].scenario.dt; };
    schedule.run = [&](std::size_t e, std::size_t c) {
        report.results[c * n_sim + e] = run_stress_case(cases[c], *request.simulators[e], request.budget_seconds);
    };
    schedule.finished = [&](std::size_t e, std::size_t c, std::size_t done) {
        if (request.on_progress) request.on_progress(report.results[c * n_sim + e], done, total);
    };
    run_pairs_in_parallel(request.simulators.size(), cases.size(), schedule);
    report.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    return report;
}

// --- output ---

namespace {

const char* short_name(Invariant i) {
    switch (i) {
        case Invariant::finite: return "finite";
        case Invariant::in_room: return "room";
        case Invariant::energy: return "energy";
        case Invariant::time_budget: return "time";
        case Invariant::flat_cost: return "cost";
    }
    return "?";
}

std::string cell(const std::vector<const StressResult*>& results) {
    if (results.size() == 1 && results.front()->row == results.front()->scenario) {
        const StressResult& r = *results.front();
        switch (r.outcome) {
            case StressOutcome::pass: return "pass";
            case StressOutcome::skipped: return "-";
            case StressOutcome::crashed: return "CRASH";
            case StressOutcome::fail: return fmt::format("FAIL {}", short_name(r.first_broken()->invariant));
        }
    }
    int pass = 0, ran = 0, crashed = 0;
    for (const StressResult* r : results) {
        if (r->outcome == StressOutcome::skipped) continue;
        ++ran;
        pass += r->outcome == StressOutcome::pass;
        crashed += r->outcome == StressOutcome::crashed;
    }
    if (ran == 0) return "-";
    std::string out = fmt::format("{}/{}", pass, ran);
    if (crashed) out += fmt::format(" {}C", crashed);
    return out;
}

std::string describe(const InvariantCheck& c) {
    switch (c.invariant) {
        case Invariant::finite: return "non-finite state";
        case Invariant::in_room:
            return fmt::format("penetration {:.4g} m > {:.4g} m (worst {:.4g} m)", c.first_value, c.tolerance, c.worst);
        case Invariant::energy:
            return fmt::format("energy rise {:.4g} J/kg > {:.4g} J/kg (worst {:.4g} J/kg)", c.first_value, c.tolerance,
                               c.worst);
        case Invariant::time_budget:
            return fmt::format("run stopped after {:.3g} s of wall time, budget {:.3g} s", c.first_value, c.tolerance);
        case Invariant::flat_cost:
            return fmt::format("late ns/step {:.3g}x early (limit {:.3g}x), first block {:.3g}x", c.worst, c.tolerance,
                               c.first_value);
    }
    return "";
}

}  // namespace

std::string format_stress_matrix(const StressReport& r) {
    const std::size_t n_sim = r.simulators.size();
    std::size_t row_width = 8;
    for (const auto& row : r.rows) row_width = std::max(row_width, row.size());
    std::string out = fmt::format("\nstress: {} rows x {} simulators, {} runs in {:.1f} s\n", r.rows.size(), n_sim,
                                  r.results.size(), r.wall_seconds);
    out += fmt::format("  {:<{}}", "scenario", row_width);
    for (const auto& sim : r.simulators) out += fmt::format(" {:>13}", sim);
    out += "\n";
    for (const auto& row : r.rows) {
        out += fmt::format("  {:<{}}", row, row_width);
        for (std::size_t e = 0; e < n_sim; ++e) {
            std::vector<const StressResult*> in_row;
            for (std::size_t i = e; i < r.results.size(); i += n_sim)
                if (r.results[i].row == row) in_row.push_back(&r.results[i]);
            out += fmt::format(" {:>13}", cell(in_row));
        }
        out += "\n";
    }
    out += "  pass: every invariant held; FAIL <first invariant broken>; - skipped; families: passed/ran, C crashed\n";
    out += fmt::format("  tolerances: finite state; room: penetration <= r/2; energy: rise <= 1% of the starting "
                       "energy + k^2 |g|^2 dt^2; time: {:g} s per run; cost: late ns/step <= {:g}x early\n",
                       r.budget_seconds, kCostRatioLimit);
    return out;
}

std::string format_stress_failures(const StressReport& r) {
    constexpr int kPerFamily = 5;
    std::string out;
    std::map<std::pair<std::string, std::string>, int> listed;  // (row, simulator) -> lines so far
    std::map<std::pair<std::string, std::string>, int> hidden;
    for (const StressResult& res : r.results) {
        if (res.outcome != StressOutcome::fail && res.outcome != StressOutcome::crashed) continue;
        const auto key = std::pair(res.row, res.simulator);
        if (res.row != res.scenario && listed[key] >= kPerFamily) {
            ++hidden[key];
            continue;
        }
        ++listed[key];
        const std::string name = res.row == res.scenario ? res.scenario : fmt::format("{}/{}", res.row, res.scenario);
        if (res.outcome == StressOutcome::crashed) {
            out += fmt::format("  {} / {}: crashed: {}\n", name, res.simulator, res.reason);
            continue;
        }
        for (const InvariantCheck& c : res.checks) {
            if (c.held) continue;
            out += fmt::format("  {} / {}: {} broke at t = {:.6g} s: {}\n", name, res.simulator, to_string(c.invariant),
                               c.first_t.value_or(0.0), describe(c));
        }
    }
    for (const auto& [key, n] : hidden)
        out += fmt::format("  {} / {}: {} more (stress.csv)\n", key.first, key.second, n);
    return out.empty() ? out : "\nbroken invariants:\n" + out;
}

namespace {

std::string csv_field(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

std::string num(double v) { return fmt::format("{:.17g}", v); }
std::string opt_num(const std::optional<double>& v) { return v ? num(*v) : ""; }


}  // namespace

std::string stress_csv(const StressReport& r) {
    std::string out = "row,scenario,simulator,outcome,first_broken,first_t,first_value,tolerance,penetration,"
                      "penetration_tol,energy_rise,energy_tol,run_seconds,cost_ratio,steps,ccd,substeps,reason\n";
    for (const StressResult& res : r.results) {
        std::string checks = ",,,,,,,,,";
        if (!res.checks.empty()) {
            const InvariantCheck* first = res.first_broken();
            const InvariantCheck& room = res.checks[1];
            const InvariantCheck& energy = res.checks[2];
            const InvariantCheck& cost = res.checks[4];
            checks = fmt::format("{},{},{},{},{},{},{},{},{},{}", first ? to_string(first->invariant) : "",
                                 first ? opt_num(first->first_t) : "", first ? num(first->first_value) : "",
                                 first ? num(first->tolerance) : "", num(room.worst), num(room.tolerance),
                                 num(energy.worst), num(energy.tolerance), num(res.run_seconds),
                                 cost.checked ? num(cost.worst) : "");
        } else {
            checks = fmt::format(",,,,,,,,{},", res.outcome == StressOutcome::skipped ? "" : num(res.run_seconds));
        }
        out += fmt::format("{},{},{},{},{},{},{},{},{}\n", res.row, res.scenario, res.simulator, to_string(res.outcome),
                           checks, res.steps, csv_field(res.ccd), csv_field(res.substeps), csv_field(res.reason));
    }
    return out;
}

nlohmann::json stress_json(const StressReport& r, const std::vector<StressCase>& cases,
                           const nlohmann::json& parameters) {
    nlohmann::json results = nlohmann::json::array();
    for (const StressResult& res : r.results) {
        nlohmann::json checks = nlohmann::json::object();
        for (const InvariantCheck& c : res.checks)
            checks[to_string(c.invariant)] = {{"checked", c.checked},       {"held", c.held},
                                              {"tolerance", json_number(c.tolerance)},
                                              {"worst", json_number(c.worst)}, {"first_t", json_number(c.first_t)},
                                              {"first_value", json_number(c.first_value)}};
        const InvariantCheck* first = res.first_broken();
        results.push_back({{"row", res.row},
                           {"scenario", res.scenario},
                           {"simulator", res.simulator},
                           {"outcome", to_string(res.outcome)},
                           {"reason", res.reason},
                           {"first_broken", first ? nlohmann::json(to_string(first->invariant)) : nlohmann::json(nullptr)},
                           {"steps", res.steps},
                           {"run_seconds", res.run_seconds},
                           {"ccd", res.ccd},
                           {"substeps", res.substeps},
                           {"invariants", checks}});
    }
    nlohmann::json generated = nlohmann::json::array();
    auto vec = [](const Scenario& s, const Vec3& v) {
        std::vector<double> out(v.data(), v.data() + s.dim);
        return out;
    };
    for (const StressCase& c : cases) {
        if (!c.generated) continue;
        const Scenario& s = c.scenario;
        generated.push_back({{"name", s.name}, {"row", c.row}, {"dim", s.dim}, {"room", vec(s, s.room)},
                             {"radius", s.radius}, {"position", vec(s, s.position)},
                             {"velocity", vec(s, s.velocity)}, {"gravity", vec(s, s.gravity)}, {"alpha", s.alpha},
                             {"beta", s.beta}, {"dt", s.dt}, {"duration", s.duration}});
    }
    return {{"schema", kStressSchema},
            {"version", BOUNCECHECK_VERSION},
            {"parameters", parameters},
            {"monte_carlo", {{"seed", kMonteCarloSeed}, {"count", kMonteCarloCount}}},
            {"tolerances",
             {{"finite", "every state component finite"},
              {"in_room", "penetration of the ball's surface beyond a wall <= radius / 2 (m)"},
              {"energy", "rise of 0.5|v|^2 - g.p above its initial value <= 1% of the energy available at the start "
                         "+ k^2 |g|^2 dt^2, k = clamp((1+alpha)/(1-alpha), 2, 20) (J/kg); when alpha, beta <= 1"},
              {"time_budget", "wall time of one run <= budget_seconds"},
              {"flat_cost", fmt::format("median ns/step of the last quarter of {}-state blocks <= {}x the first "
                                        "quarter's; judged from {} blocks",
                                        kCostBlockSteps, kCostRatioLimit, kCostMinBlocks)}}},
            {"rows", r.rows},
            {"simulators", r.simulators},
            {"wall_seconds", r.wall_seconds},
            {"results", std::move(results)},
            {"generated_scenarios", std::move(generated)}};
}

void write_stress(const StressReport& r, const std::vector<StressCase>& cases, const nlohmann::json& parameters,
                  const std::filesystem::path& out_dir) {
    write_file_atomically(out_dir / "stress.csv", stress_csv(r));
    write_file_atomically(out_dir / "stress.json", stress_json(r, cases, parameters).dump(2) + "\n");
    // A generated scenario that broke something, as a file `bouncecheck run` reproduces.
    std::set<std::string> written;
    for (const StressResult& res : r.results) {
        if (res.outcome != StressOutcome::fail && res.outcome != StressOutcome::crashed) continue;
        const auto c = std::find_if(cases.begin(), cases.end(),
                                    [&](const StressCase& k) { return k.generated && k.scenario.name == res.scenario; });
        if (c == cases.end() || !written.insert(res.scenario).second) continue;
        std::filesystem::create_directories(out_dir / kStressScenarioDir);
        write_file_atomically(out_dir / kStressScenarioDir / (res.scenario + ".toml"), scenario_toml(c->scenario));
    }
}

}  // namespace bouncecheck
