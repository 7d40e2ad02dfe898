#include "reports/stress_report.h"

#include "platform/atomic_file.h"
#include "reports/json_number.h"
#include "scenarios/scenario_toml.h"

#include <fmt/format.h>

#include <algorithm>
#include <functional>
#include <map>
#include <set>

namespace bouncecheck {

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
        case StressOutcome::hung: return "hung";
    }
    return "?";
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
            case StressOutcome::hung: return "HUNG";
            case StressOutcome::fail: return fmt::format("FAIL {}", short_name(r.first_broken()->invariant));
        }
    }
    int pass = 0, ran = 0, crashed = 0, hung = 0;
    for (const StressResult* r : results) {
        if (r->outcome == StressOutcome::skipped) continue;
        ++ran;
        pass += r->outcome == StressOutcome::pass;
        crashed += r->outcome == StressOutcome::crashed;
        hung += r->outcome == StressOutcome::hung;
    }
    if (ran == 0) return "-";
    std::string out = fmt::format("{}/{}", pass, ran);
    if (crashed) out += fmt::format(" {}C", crashed);
    if (hung) out += fmt::format(" {}H", hung);
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
    std::string out = fmt::format("\nstress: {} rows x {} simulators, {} runs", r.rows.size(), n_sim, r.results.size());
    out += std::isnan(r.wall_seconds) ? "\n" : fmt::format(" in {:.1f} s\n", r.wall_seconds);
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
    out += "  pass: every invariant held; FAIL <first invariant broken>; - skipped; CRASH; HUNG killed by the "
           "watchdog; families: passed/ran, C crashed, H hung\n";
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
        if (res.outcome == StressOutcome::pass || res.outcome == StressOutcome::skipped) continue;
        const auto key = std::pair(res.row, res.simulator);
        if (res.row != res.scenario && listed[key] >= kPerFamily) {
            ++hidden[key];
            continue;
        }
        ++listed[key];
        const std::string name = res.row == res.scenario ? res.scenario : fmt::format("{}/{}", res.row, res.scenario);
        if (res.outcome == StressOutcome::crashed || res.outcome == StressOutcome::hung) {
            out += fmt::format("  {} / {}: {}: {}\n", name, res.simulator, to_string(res.outcome), res.reason);
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
// A wall-clock figure: NaN when left out (--no-timings).
std::string timing_num(double v) { return std::isnan(v) ? "" : num(v); }


}  // namespace

void leave_out_timings(StressReport& r) {
    const double none = std::nan("");
    r.wall_seconds = none;
    for (StressResult& res : r.results) {
        res.run_seconds = none;
        for (InvariantCheck& c : res.checks)
            if (c.invariant == Invariant::time_budget || c.invariant == Invariant::flat_cost) {
                c.worst = none;
                c.first_value = none;
            }
    }
}

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
                                 num(energy.worst), num(energy.tolerance), timing_num(res.run_seconds),
                                 cost.checked ? timing_num(cost.worst) : "");
        } else {
            checks = fmt::format(",,,,,,,,{},", res.outcome == StressOutcome::skipped ? "" : timing_num(res.run_seconds));
        }
        out += fmt::format("{},{},{},{},{},{},{},{},{}\n", res.row, res.scenario, res.simulator, to_string(res.outcome),
                           checks, res.steps, csv_field(res.ccd), csv_field(res.substeps), csv_field(res.reason));
    }
    return out;
}

namespace {

nlohmann::json result_json(const StressResult& res) {
    nlohmann::json checks = nlohmann::json::object();
    for (const InvariantCheck& c : res.checks)
        checks[to_string(c.invariant)] = {{"checked", c.checked},       {"held", c.held},
                                          {"tolerance", json_number(c.tolerance)},
                                          {"worst", json_number(c.worst)}, {"first_t", json_number(c.first_t)},
                                          {"first_value", json_number(c.first_value)}};
    const InvariantCheck* first = res.first_broken();
    return {{"row", res.row},
            {"scenario", res.scenario},
            {"simulator", res.simulator},
            {"outcome", to_string(res.outcome)},
            {"reason", res.reason},
            {"first_broken", first ? nlohmann::json(to_string(first->invariant)) : nlohmann::json(nullptr)},
            {"steps", res.steps},
            {"run_seconds", json_number(res.run_seconds)},
            {"ccd", res.ccd},
            {"substeps", res.substeps},
            {"invariants", checks}};
}

nlohmann::json generated_json(const StressCase& c) {
    const Scenario& s = c.scenario;
    const auto vec = [&](const Vec3& v) { return std::vector<double>(v.data(), v.data() + s.dim); };
    return {{"name", s.name},         {"row", c.row},         {"dim", s.dim},
            {"room", vec(s.room)},    {"radius", s.radius},   {"position", vec(s.position)},
            {"velocity", vec(s.velocity)}, {"gravity", vec(s.gravity)}, {"alpha", s.alpha},
            {"beta", s.beta},         {"dt", s.dt},           {"duration", s.duration}};
}

// Where the document's two long arrays go: its head is dumped with these
// strings in their place, then cut there.
constexpr const char* kResultsSlot = "@bouncecheck-stress-results@";
constexpr const char* kGeneratedSlot = "@bouncecheck-stress-generated@";

// A JSON array at depth 1 of a document dumped with indent 2, written an
// element at a time: each element dumped alone, its lines indented to depth
// 2 (no JSON string holds a raw line break). Nothing but one element and a
// megabyte of text is in memory at once.
void write_array(AtomicFile& file, std::size_t n, const std::function<nlohmann::json(std::size_t)>& element) {
    if (n == 0) return file.write("[]");
    std::string text = "[\n";
    for (std::size_t i = 0; i < n; ++i) {
        text += "    ";
        for (const char c : json_text(element(i), 2)) {
            text += c;
            if (c == '\n') text += "    ";
        }
        text += i + 1 < n ? ",\n" : "\n";
        if (text.size() > (std::size_t{1} << 20)) {
            file.write(text);
            text.clear();
        }
    }
    file.write(text + "  ]");
}

// stress.json: the document nlohmann's dump(2) would write, written in pieces
// so that its memory does not grow with the suite (a merged run of a million
// Monte-Carlo scenarios and seven engines has seven million results).
void write_stress_json(const std::filesystem::path& target, const StressReport& r,
                       const std::vector<StressCase>& cases, const nlohmann::json& parameters,
                       const nlohmann::json& provenance) {
    nlohmann::json head = {{"schema", kStressSchema},
            {"version", BOUNCECHECK_VERSION},
            {"parameters", parameters},
            {"monte_carlo", {{"seed", r.monte_carlo.seed}, {"count", r.monte_carlo.count}}},
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
            {"wall_seconds", json_number(r.wall_seconds)},
            {"results", kResultsSlot},
            {"generated_scenarios", kGeneratedSlot}};
    if (!provenance.is_null()) head["provenance"] = provenance;
    const std::string text = json_text(head, 2) + "\n";
    std::vector<const StressCase*> generated;
    for (const StressCase& c : cases)
        if (c.generated) generated.push_back(&c);

    AtomicFile file(target);
    std::size_t from = 0;
    // The two slots in the order the (sorted) keys put them.
    const std::string results_slot = fmt::format("\"{}\"", kResultsSlot);
    const std::string generated_slot = fmt::format("\"{}\"", kGeneratedSlot);
    for (std::size_t at; (at = std::min(text.find(results_slot, from), text.find(generated_slot, from))) !=
                         std::string::npos;) {
        file.write(std::string_view(text).substr(from, at - from));
        if (text.compare(at, results_slot.size(), results_slot) == 0) {
            write_array(file, r.results.size(), [&](std::size_t i) { return result_json(r.results[i]); });
            from = at + results_slot.size();
        } else {
            write_array(file, generated.size(), [&](std::size_t i) { return generated_json(*generated[i]); });
            from = at + generated_slot.size();
        }
    }
    file.write(std::string_view(text).substr(from));
    file.commit();
}

}  // namespace

WrittenFiles write_stress(const StressReport& r, const std::vector<StressCase>& cases, const nlohmann::json& parameters,
                  const std::filesystem::path& out_dir, const nlohmann::json& provenance) {
    WrittenFiles written = {"stress.csv", "stress.json"};
    OutputWrites writes;  // one file that cannot be written costs only itself
    writes.attempt([&] { write_file_atomically(out_dir / "stress.csv", stress_csv(r)); });
    writes.attempt([&] { write_stress_json(out_dir / "stress.json", r, cases, parameters, provenance); });
    // A generated scenario that broke something, as a file `bouncecheck run` reproduces.
    std::map<std::string, const StressCase*> generated;
    for (const StressCase& c : cases)
        if (c.generated) generated.emplace(c.scenario.name, &c);
    std::set<std::string> scenarios_written;
    for (const StressResult& res : r.results) {
        if (res.outcome == StressOutcome::pass || res.outcome == StressOutcome::skipped) continue;
        const auto c = generated.find(res.scenario);
        if (c == generated.end() || !scenarios_written.insert(res.scenario).second) continue;
        const std::string file = std::string(kStressScenarioDir) + "/" + res.scenario + ".toml";
        writes.attempt([&] {
            std::filesystem::create_directories(out_dir / kStressScenarioDir);
            write_file_atomically(out_dir / file, scenario_toml(c->second->scenario));
        });
        written.push_back(file);
    }
    writes.finish();
    return written;
}

}  // namespace bouncecheck
