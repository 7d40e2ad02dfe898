#include "reports/engine_table.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <optional>
#include <string_view>

namespace bouncecheck {

namespace {

using nlohmann::json;

// Any report that passed load_run_report's checks may still hold any type
// anywhere below its top level: every read is checked.
const json* member(const json& j, std::string_view key) {
    if (!j.is_object()) return nullptr;
    const auto it = j.find(key);
    return it == j.end() ? nullptr : &*it;
}

// The member at a path of keys, or nullptr.
const json* at(const json& j, std::initializer_list<std::string_view> keys) {
    const json* here = &j;
    for (const std::string_view key : keys)
        if (!(here = member(*here, key))) return nullptr;
    return here;
}

std::optional<double> number(const json* j) {
    if (!j || !j->is_number()) return std::nullopt;
    const double v = j->get<double>();
    return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

std::string text(const json* j) { return j && j->is_string() ? j->get<std::string>() : std::string(); }

// A settings value by key ("engine", "precision"), or "".
std::string setting(const json& simulator, std::string_view key) {
    const json* settings = member(simulator, "settings");
    if (!settings || !settings->is_array()) return {};
    for (const json& s : *settings)
        if (text(member(s, "key")) == key) return text(member(s, "value"));
    return {};
}

// A table cell: no pipe or line break may end the cell early.
std::string cell(std::string s) {
    for (char& c : s)
        if (c == '|' || c == '\n' || c == '\r') c = ' ';
    return s.empty() ? "-" : s;
}

// An engine's text as a cell: a long one without its parenthesis (ODE's
// lists its build flags there).
std::string short_engine(const std::string& engine) {
    constexpr std::size_t kLongest = 72;
    return engine.size() > kLongest ? engine.substr(0, engine.find(" (")) : engine;
}

// The precision in one vocabulary: the compiled engines say "double (...)"
// or "float", the Node-hosted ones "f64" or "f32".
std::string short_precision(const std::string& precision) {
    const std::string word = precision.substr(0, precision.find(" ("));
    return word == "double" ? "f64" : word == "float" ? "f32" : word;
}

std::string percent(std::optional<double> v) { return v ? fmt::format("{:.3f}%", 100 * *v) : "-"; }
std::string fixed(std::optional<double> v, int digits) { return v ? fmt::format("{:.{}f}", *v, digits) : "-"; }

// What each row is judged against: exact's run of the same scenario.
struct ExactBaseline {
    std::optional<double> first_floor_contact;  // exact's first floor contact (s)
    std::size_t first_apex = 1;  // 1 where the start is itself an apex (exact's first at t = 0), else 0
};

// The time of a simulator's first floor contact (first_floor_contacts[0].t).
std::optional<double> first_floor_contact(const json& simulator) {
    const json* contacts = member(simulator, "first_floor_contacts");
    if (!contacts || !contacts->is_array() || contacts->empty()) return std::nullopt;
    return number(member(contacts->front(), "t"));
}

ExactBaseline exact_baseline(const json& simulators) {
    ExactBaseline out;
    for (const json& simulator : simulators)
        if (text(member(simulator, "simulator")) == "exact") {
            out.first_floor_contact = first_floor_contact(simulator);
            const json* apexes = member(simulator, "apexes");
            if (apexes && apexes->is_array() && !apexes->empty())
                out.first_apex = number(member(apexes->front(), "t")) == 0.0 ? 1 : 0;
        }
    return out;
}

// The first floor contact's time against exact's, relative; the worst of the
// three apexes after the start, relative to exact's height above the floor
// (comparison.vs_exact.bounces, in order): as the law's check judges them
// (api/law_check.cpp).
struct AgainstExact {
    std::optional<double> first_contact, worst_apex;
    int apexes = 0;  // of the three that both have
};

AgainstExact against_exact(const json& simulator, const ExactBaseline& exact) {
    AgainstExact out;
    const auto t = first_floor_contact(simulator);
    if (t && exact.first_floor_contact && *exact.first_floor_contact != 0)
        out.first_contact = std::abs(*t - *exact.first_floor_contact) / std::abs(*exact.first_floor_contact);
    const json* bounces = at(simulator, {"comparison", "vs_exact", "bounces"});
    if (!bounces || !bounces->is_array()) return out;
    for (std::size_t k = exact.first_apex; k < bounces->size() && k < exact.first_apex + 3; ++k)
        if (const auto rel = number(member((*bounces)[k], "rel_diff"))) {
            out.worst_apex = std::max(out.worst_apex.value_or(0), std::abs(*rel));
            ++out.apexes;
        }
    return out;
}

std::string row(const std::string& scenario, const json& simulator, const ExactBaseline& exact) {
    const std::string name = cell(text(member(simulator, "simulator")));
    const std::string status = text(member(simulator, "status"));
    const std::string engine = cell(short_engine(setting(simulator, "engine")));
    const std::string precision = cell(short_precision(setting(simulator, "precision")));
    if (status != "ok")
        return fmt::format("| {} | {} | {} | {} | {} | | | | | |\n", cell(scenario), name, engine, precision,
                           cell(status.empty() ? "no status" : status));
    const AgainstExact e = against_exact(simulator, exact);
    const json* damping = at(simulator, {"comparison", "damping"});
    static const json no_damping = json::object();
    const json& d = damping ? *damping : no_damping;
    const bool has_normal = number(member(d, "contacts")).value_or(0) > 0;
    const bool has_tangential = number(member(d, "tangential_contacts")).value_or(0) > 0;
    const json* rest = member(simulator, "rest_time");
    const std::string rest_text = rest && rest->is_null() ? "none" : fixed(number(rest), 3);
    return fmt::format("| {} | {} | {} | {} | {} | {}{} | {} | {} | {} | {} |\n", cell(scenario), name, engine,
                       precision, percent(e.first_contact), percent(e.worst_apex),
                       e.worst_apex && e.apexes < 3 ? fmt::format(" ({} of 3)", e.apexes) : "",
                       has_normal ? fixed(number(member(d, "normal_mean")), 4) : "-",
                       has_tangential ? fixed(number(member(d, "tangential_mean")), 4) : "-", rest_text,
                       fixed(number(member(simulator, "ns_per_step")), 0));
}

}  // namespace

std::string engine_table_markdown(const json& report) {
    std::string out =
        "| scenario | simulator | engine | precision | first floor contact vs exact | 3 apexes after the start vs exact (worst) "
        "| alpha measured | beta measured | rest (s) | ns/step |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n";
    const json* scenarios = member(report, "scenarios");
    if (!scenarios || !scenarios->is_array()) return out;
    for (const json& sc : *scenarios) {
        const std::string name = text(at(sc, {"scenario", "name"}));
        const json* simulators = member(sc, "simulators");
        if (!simulators || !simulators->is_array()) continue;
        const ExactBaseline exact = exact_baseline(*simulators);
        for (const json& simulator : *simulators)
            if (text(member(simulator, "status")) != "skipped") out += row(name, simulator, exact);  // else: not its dimension
    }
    return out;
}

}  // namespace bouncecheck
