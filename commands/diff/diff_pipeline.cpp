#include "commands/diff/diff_pipeline.h"

#include "platform/bounded_read.h"

#include "platform/did_you_mean.h"
#include "platform/printable_text.h"
#include "reports/provenance.h"
#include "reports/run_report.h"
#include "reports/stress_report.h"
#include "reports/json_number.h"
#include "reports/sweep_report.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

using json = nlohmann::json;

const json kAbsent = json::value_t::discarded;  // a field one side lacks

const json& field(const json& object, const std::string& key) {
    if (!object.is_object()) return kAbsent;
    const auto it = object.find(key);
    return it == object.end() ? kAbsent : *it;
}

const json& element(const json& array, std::size_t i) {
    return array.is_array() && i < array.size() ? array[i] : kAbsent;
}

std::size_t size_of(const json& array) { return array.is_array() ? array.size() : 0; }

std::string show(const json& v) {
    if (v.is_discarded()) return "absent";
    if (v.is_null()) return "null";
    if (v.is_string()) return v.get<std::string>();
    if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
    if (v.is_number_float()) return fmt::format("{:.10g}", v.get<double>());
    return json_text(v);
}

// Compares one scenario (its inputs) or one of its simulators, field by field, into `out`.
class Differ {
public:
    Differ(const DiffTolerances& tolerances, ReportDiff& out, std::string scenario, std::string simulator)
        : tolerances_(tolerances), out_(out), scenario_(std::move(scenario)), simulator_(std::move(simulator)) {}

    // Any difference at all counts (inputs, statuses, counts, verdicts, settings).
    void exact(DiffSection section, const std::string& kind, const std::string& metric, const json& a, const json& b) {
        if (a.is_discarded() && b.is_discarded()) return;
        if (a.is_discarded() != b.is_discarded() || a != b) push(section, kind, metric, a, b, "", std::nullopt);
    }
    void exact(const std::string& kind, const std::string& metric, const json& a, const json& b) {
        exact(DiffSection::consequence, kind, metric, a, b);
    }

    // A consequence that is a number: a change beyond the tolerance `key`
    // counts; null (not finite) or absent on one side only counts too.
    void number(const std::string& kind, const std::string& metric, const std::string& key, const json& a,
                const json& b) {
        if (a.is_number() && b.is_number()) {
            const double delta = b.get<double>() - a.get<double>();
            if (std::abs(delta) > tolerances_.by_key.at(key))
                push(DiffSection::consequence, kind, metric, a, b, key, delta);
            return;
        }
        if (a.is_discarded() && b.is_discarded()) return;
        if (a == b) return;  // the same on both sides, number or not (a report diffed with itself shows nothing)
        push(DiffSection::consequence, kind, metric, a, b, key, std::nullopt);
    }

private:
    void push(DiffSection section, const std::string& kind, const std::string& metric, const json& a, const json& b,
              const std::string& key, std::optional<double> delta) {
        std::optional<double> numeric = delta;
        if (!numeric && section != DiffSection::consequence && a.is_number() && b.is_number())
            numeric = b.get<double>() - a.get<double>();
        out_.changes.push_back({section, scenario_, simulator_, metric, kind, show(a), show(b), key, numeric, {}});
    }

    const DiffTolerances& tolerances_;
    ReportDiff& out_;
    std::string scenario_, simulator_;
};

std::map<std::string, json> by_key(const json& array, const char* key, const char* value) {
    std::map<std::string, json> out;
    if (!array.is_array()) return out;
    for (const json& item : array)
        if (item.is_object() && field(item, key).is_string()) out[item[key].get<std::string>()] = field(item, value);
    return out;
}

// Each key of either map, with its value on both sides (kAbsent where one lacks it).
template <typename F>
void for_each_key_of_both(const std::map<std::string, json>& a, const std::map<std::string, json>& b, F&& f) {
    std::set<std::string> keys;
    for (const auto& [k, v] : a) keys.insert(k);
    for (const auto& [k, v] : b) keys.insert(k);
    for (const std::string& k : keys) {
        const auto ia = a.find(k), ib = b.find(k);
        f(k, ia == a.end() ? kAbsent : ia->second, ib == b.end() ? kAbsent : ib->second);
    }
}

void diff_maps(Differ& d, DiffSection section, const std::string& kind, const std::string& prefix,
               const std::map<std::string, json>& a, const std::map<std::string, json>& b) {
    for_each_key_of_both(a, b, [&](const std::string& k, const json& x, const json& y) {
        d.exact(section, kind, prefix + k, x, y);
    });
}

std::map<std::string, json> members(const json& object) {
    std::map<std::string, json> out;
    if (object.is_object())
        for (const auto& [k, v] : object.items()) out[k] = v;
    return out;
}

// The scenario's inputs, named as the scenario file writes them: report.json's
// "scenario" holds each value the loader read (reports/run_report.cpp).
void diff_inputs(Differ& d, const json& a, const json& b) {
    static constexpr std::pair<const char*, const char*> kFields[] = {
        {"dim", "dimensions (from [room] size)"}, {"room", "[room] size"},         {"radius", "[ball] radius"},
        {"position", "[ball] position"},          {"velocity", "[ball] velocity"}, {"gravity", "[world] gravity"},
        {"alpha", "[damping] normal"},            {"beta", "[damping] tangential"}, {"dt", "[run] dt"},
        {"duration", "[run] duration"},
    };
    for (const auto& [field_name, input] : kFields)
        d.exact(DiffSection::input, "inputs", input, field(a, field_name), field(b, field_name));
    // Each [engines.NAME] and [thresholds.NAME] table key by key: a table
    // added or removed shows as each of its keys, absent on one side.
    const auto tables = [&](const std::string& section, const json& x, const json& y) {
        for_each_key_of_both(members(x), members(y), [&](const std::string& name, const json& p, const json& q) {
            diff_maps(d, DiffSection::input, "inputs", "[" + section + "." + name + "] ", members(p), members(q));
        });
    };
    tables("engines", field(a, "engines"), field(b, "engines"));
    const json &ta = field(a, "thresholds"), &tb = field(b, "thresholds");
    diff_maps(d, DiffSection::input, "inputs", "[thresholds] ", members(field(ta, "all")), members(field(tb, "all")));
    tables("thresholds", field(ta, "simulators"), field(tb, "simulators"));
}

// Why each setting change happened: the first input of its scenario that
// changed, its own engine table's first; none: no input explains it.
void explain_settings(ReportDiff& out) {
    for (DiffChange& setting : out.changes) {
        if (setting.section != DiffSection::setting) continue;
        const DiffChange* first = nullptr;
        const std::string own_table = "[engines." + setting.simulator + "]";
        for (const DiffChange& input : out.changes) {
            if (input.section != DiffSection::input || input.scenario != setting.scenario) continue;
            if (input.metric.rfind(own_table, 0) == 0) {
                first = &input;
                break;
            }
            if (!first && input.metric.rfind("[engines.", 0) != 0 && input.metric.rfind("[thresholds", 0) != 0)
                first = &input;
        }
        if (first) setting.cause = first->metric;
    }
}

// Field by field, what explains a change first (status, settings, verdicts),
// then what it moved (counts, distances, damping, bounce by bounce).
void diff_simulator(Differ& d, const json& a, const json& b) {
    d.exact("status", "status", field(a, "status"), field(b, "status"));
    d.exact("status", "reason", field(a, "reason"), field(b, "reason"));
    if (field(a, "status") == "skipped" || field(b, "status") == "skipped") return;
    diff_maps(d, DiffSection::setting, "settings", "", by_key(field(a, "settings"), "key", "value"),
              by_key(field(b, "settings"), "key", "value"));
    const json &ca = field(a, "comparison"), &cb = field(b, "comparison");
    const json &da = field(ca, "damping"), &db = field(cb, "damping");
    d.exact("damping verdict", "damping verdict", field(da, "verdict"), field(db, "verdict"));
    diff_maps(d, DiffSection::consequence, "thresholds", "threshold ", by_key(field(ca, "thresholds"), "metric", "passed"),
              by_key(field(cb, "thresholds"), "metric", "passed"));
    for (const char* count : {"steps", "contacts", "floor_contacts", "apex_count"})
        d.exact("counts", count, field(a, count), field(b, count));
    for (const char* baseline : {"vs_reference", "vs_exact"})
        for (const char* measure : {"rms", "max"})
            d.number("trajectory", fmt::format("trajectory {} {}", measure, baseline), "trajectory",
                     field(field(field(ca, baseline), "trajectory"), measure),
                     field(field(field(cb, baseline), "trajectory"), measure));
    d.number("measured damping", "measured alpha", "damping", field(da, "normal_mean"), field(db, "normal_mean"));
    d.number("measured damping", "measured beta", "damping", field(da, "tangential_mean"), field(db, "tangential_mean"));
    d.number("rest time", "rest_time", "time", field(a, "rest_time"), field(b, "rest_time"));

    const json &apexes_a = field(a, "apexes"), &apexes_b = field(b, "apexes");
    for (std::size_t i = 0; i < std::max(size_of(apexes_a), size_of(apexes_b)); ++i) {
        const json &x = element(apexes_a, i), &y = element(apexes_b, i);
        d.number("apex heights", fmt::format("apex[{}].height", i + 1), "height", field(x, "height"), field(y, "height"));
        d.number("apex times", fmt::format("apex[{}].t", i + 1), "time", field(x, "t"), field(y, "t"));
    }
    const json &floor_a = field(a, "first_floor_contacts"), &floor_b = field(b, "first_floor_contacts");
    for (std::size_t i = 0; i < std::max(size_of(floor_a), size_of(floor_b)); ++i) {
        const json &x = element(floor_a, i), &y = element(floor_b, i);
        d.number("contact times", fmt::format("floor_contact[{}].t", i + 1), "time", field(x, "t"), field(y, "t"));
        d.number("contact restitution", fmt::format("floor_contact[{}].alpha", i + 1), "damping",
                 field(x, "restitution"), field(y, "restitution"));
    }
    for (const char* part : {"position", "velocity"}) {
        const json &pa = field(field(a, "final_state"), part), &pb = field(field(b, "final_state"), part);
        for (std::size_t i = 0; i < std::max(size_of(pa), size_of(pb)); ++i)
            d.number("final state", fmt::format("final {}[{}]", part, i), "state", element(pa, i), element(pb, i));
    }
}

void diff_timing(ReportDiff& out, const std::string& scenario, const std::string& simulator, const json& a,
                 const json& b, std::optional<double> limit) {
    const json &ta = field(a, "run_seconds"), &tb = field(b, "run_seconds");
    if (!ta.is_number() || !tb.is_number() || ta.get<double>() <= 0) return;  // --no-timings, or not run
    TimingChange t{scenario, simulator, ta.get<double>(), tb.get<double>(), tb.get<double>() / ta.get<double>()};
    t.regression = limit && t.ratio > *limit;
    out.timings.push_back(t);
}

std::map<std::string, const json*> named(const json& array, const char* key) {
    std::map<std::string, const json*> out;
    for (const json& item : array) out[item[key].get<std::string>()] = &item;
    return out;
}

// Why `j` is not a run report this bouncecheck reads, if it is not.
std::optional<std::string> not_a_run_report(const json& j) {
    if (!j.is_object() || !j.contains("schema") || !j["schema"].is_string())
        return "not a bouncecheck report: it has no \"schema\" field";
    const std::string schema = j["schema"];
    if (schema == kSweepSchema || schema == kStressSchema)
        return fmt::format("a {} report ({}): diff compares run reports (report.json of `bouncecheck run`)",
                           schema == kSweepSchema ? "sweep" : "stress", schema);
    if (schema != kReportSchema)
        return fmt::format("schema \"{}\", which this bouncecheck cannot read: it reads \"{}\" (compare reports "
                           "written by one bouncecheck version, or rerun the old one)",
                           schema, kReportSchema);
    if (!j.contains("scenarios") || !j["scenarios"].is_array()) return "no \"scenarios\" array";
    // Each name once: a scenario or simulator listed twice would diff as whichever came last.
    std::set<std::string> scenarios;
    for (std::size_t i = 0; i < j["scenarios"].size(); ++i) {
        const json& sc = j["scenarios"][i];
        if (!field(field(sc, "scenario"), "name").is_string())
            return fmt::format("scenarios[{}]: no scenario.name", i);
        const std::string name = sc["scenario"]["name"].get<std::string>();
        if (!scenarios.insert(name).second)
            return fmt::format("scenarios[{}]: scenario '{}' listed twice", i, printable_text(name));
        if (!field(sc, "simulators").is_array()) return fmt::format("scenarios[{}]: no \"simulators\" array", i);
        std::set<std::string> simulators;
        for (std::size_t k = 0; k < sc["simulators"].size(); ++k) {
            const json& sim = field(sc["simulators"][k], "simulator");
            if (!sim.is_string()) return fmt::format("scenarios[{}].simulators[{}]: no \"simulator\" name", i, k);
            if (!simulators.insert(sim.get<std::string>()).second)
                return fmt::format("scenarios[{}].simulators[{}]: simulator '{}' listed twice", i, k,
                                   printable_text(sim.get<std::string>()));
        }
    }
    return std::nullopt;
}

}  // namespace

std::optional<std::string> parse_tolerance(const std::string& arg, DiffTolerances& t) {
    const auto eq = arg.find('=');
    if (eq == std::string::npos) return fmt::format("'{}' is not KEY=VALUE", arg);
    const std::string key = arg.substr(0, eq), text = arg.substr(eq + 1);
    const auto it = t.by_key.find(key);
    if (it == t.by_key.end()) {
        std::vector<std::string> keys;
        for (const auto& [k, v] : t.by_key) keys.push_back(k);
        return fmt::format("'{}': unknown key{} ({})", key, did_you_mean(key, keys), fmt::join(keys, ", "));
    }
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(value) || value < 0)
        return fmt::format("'{}': the tolerance must be a finite number >= 0", arg);
    it->second = value;
    return std::nullopt;
}

std::optional<DiffTolerances> DiffJudging::tolerances() const {
    DiffTolerances t;
    bool ok = true;
    for (const std::string& arg : tolerance_args) {
        if (auto error = parse_tolerance(arg, t)) {
            fmt::print(stderr, "error: --tolerance {}\n", *error);
            ok = false;
        }
    }
    if (!ok) return std::nullopt;
    return t;
}

namespace {

// Every string of a report, keys included, as printable_text makes it: a
// report is outside bytes, and diff prints its names, reasons and settings
// on the terminal and in diff.md (a scenario named with ESC[2J cleared the
// screen). Nesting is already bounded by the reader.
json printable_strings(const json& j) {
    if (j.is_string()) return printable_text(j.get_ref<const std::string&>());
    if (j.is_array()) {
        json out = json::array();
        for (const json& item : j) out.push_back(printable_strings(item));
        return out;
    }
    if (j.is_object()) {
        json out = json::object();
        for (const auto& [key, value] : j.items()) out[printable_text(key)] = printable_strings(value);
        return out;
    }
    return j;
}

}  // namespace

std::variant<LoadedReport, std::string> load_run_report(const fs::path& path) {
    std::error_code ec;
    fs::path file = path;
    if (fs::is_directory(path, ec)) {
        file = path / "report.json";
        if (!fs::exists(file, ec))
            return fmt::format("{}: holds no report.json (the output folder of `bouncecheck run`?)", printable_text(path.string()));
    }
    const std::string shown = printable_text(file.string());  // a path is outside bytes too
    if (!fs::exists(file, ec)) return fmt::format("{}: no such file", shown);
    // Refused from its size, before it is read (a 2 GB file cost 4 GB and 11 s
    // to be called "not JSON"); read once, without waiting on a FIFO.
    auto read = read_bounded(file, kMaxRunReportBytes);
    if (auto* refused = std::get_if<ReadRefusal>(&read)) {
        if (refused->reason.find("over the limit") != std::string::npos)
            return fmt::format("{}: {} for a report", shown, refused->reason);
        return fmt::format("{}: {}", shown, refused->reason);
    }
    const std::string& text = std::get<std::string>(read);
    LoadedReport report{json(), shown};
    // Nesting past any report's is refused as it is read.
    const json::parser_callback_t depth_limit = [](int depth, json::parse_event_t, json&) {
        if (depth > kMaxRunReportDepth) throw std::runtime_error(fmt::format("nested deeper than {} levels", kMaxRunReportDepth));
        return true;
    };
    try {
        report.json = json::parse(text, depth_limit);
    } catch (const json::exception& e) {  // parse_error, and out_of_range for a number like 1e400
        return fmt::format("{}: not JSON this bouncecheck can read: {}", shown, error_text(e));
    } catch (const std::runtime_error& e) {
        return fmt::format("{}: {}", shown, e.what());
    }
    if (auto why = not_a_run_report(report.json)) return fmt::format("{}: {}", shown, *why);
    report.json = printable_strings(report.json);
    return report;
}

ReportDiff diff_reports(const LoadedReport& old_report, const LoadedReport& new_report,
                        const DiffTolerances& tolerances, std::optional<double> timing_ratio) {
    ReportDiff out;
    out.old_source = old_report.source;
    out.new_source = new_report.source;
    out.old_provenance = format_provenance(field(old_report.json, "provenance"));
    out.new_provenance = format_provenance(field(new_report.json, "provenance"));
    out.tolerances = tolerances.by_key;
    out.timing_ratio = timing_ratio;

    const json &old_scenarios = old_report.json["scenarios"], &new_scenarios = new_report.json["scenarios"];
    std::vector<std::string> order;  // old's order, then what only new has
    std::map<std::string, const json*> olds, news;
    for (const json& sc : old_scenarios) order.push_back(sc["scenario"]["name"]), olds[order.back()] = &sc;
    for (const json& sc : new_scenarios) {
        const std::string name = sc["scenario"]["name"];
        if (!olds.count(name)) order.push_back(name);
        news[name] = &sc;
    }
    for (const std::string& name : order) {
        const auto a = olds.find(name), b = news.find(name);
        if (a == olds.end() || b == news.end()) {
            out.changes.push_back({DiffSection::consequence, name, "", "scenario", "presence",
                                   a == olds.end() ? "absent" : "present", b == news.end() ? "absent" : "present", "",
                                   std::nullopt, {}});
            continue;
        }
        Differ inputs(tolerances, out, name, "");
        diff_inputs(inputs, (*a->second)["scenario"], (*b->second)["scenario"]);
        const json &sims_a = (*a->second)["simulators"], &sims_b = (*b->second)["simulators"];
        const auto by_name_a = named(sims_a, "simulator"), by_name_b = named(sims_b, "simulator");
        std::vector<std::string> sims;
        for (const json& s : sims_a) sims.push_back(s["simulator"]);
        for (const json& s : sims_b)
            if (!by_name_a.count(s["simulator"].get<std::string>())) sims.push_back(s["simulator"]);
        for (const std::string& sim : sims) {
            const auto x = by_name_a.find(sim), y = by_name_b.find(sim);
            if (x == by_name_a.end() || y == by_name_b.end()) {
                out.changes.push_back({DiffSection::consequence, name, sim, "simulator", "presence",
                                       x == by_name_a.end() ? "absent" : "present",
                                       y == by_name_b.end() ? "absent" : "present", "", std::nullopt, {}});
                continue;
            }
            Differ d(tolerances, out, name, sim);
            diff_simulator(d, *x->second, *y->second);
            diff_timing(out, name, sim, *x->second, *y->second, timing_ratio);
        }
    }
    // Inputs first, then settings, then consequences, each in the order found.
    std::stable_sort(out.changes.begin(), out.changes.end(),
                     [](const DiffChange& x, const DiffChange& y) { return x.section < y.section; });
    explain_settings(out);
    return out;
}

}  // namespace bouncecheck
