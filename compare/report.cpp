#include "compare/report.h"

#include "compare/atomic_file.h"

#include <fmt/format.h>

#include <iterator>

namespace bouncecheck {

namespace {

nlohmann::json vec_json(const Vec3& v, int dim) {
    nlohmann::json a = nlohmann::json::array();
    for (int i = 0; i < dim; ++i) a.push_back(v[i]);
    return a;
}

nlohmann::json scenario_json(const Scenario& s) {
    return {
        {"name", s.name},
        {"file", s.source.string()},
        {"dim", s.dim},
        {"room", vec_json(s.room, s.dim)},
        {"radius", s.radius},
        {"position", vec_json(s.position, s.dim)},
        {"velocity", vec_json(s.velocity, s.dim)},
        {"gravity", vec_json(s.gravity, s.dim)},
        {"alpha", s.alpha},
        {"beta", s.beta},
        {"dt", s.dt},
        {"duration", s.duration},
    };
}

nlohmann::json result_json(const SimulatorSummary& r, int dim) {
    nlohmann::json j = {{"simulator", r.simulator}, {"status", to_string(r.status)}};
    if (!r.reason.empty()) j["reason"] = r.reason;
    if (r.status == RunStatus::skipped) return j;
    j["steps"] = r.steps;
    j["contacts"] = r.contacts;
    j["floor_contacts"] = r.floor_contacts;
    j["contacts_unbounded"] = r.contacts_unbounded;
    j["apex_count"] = r.apex_count;
    nlohmann::json apexes = nlohmann::json::array();
    for (const Apex& a : r.apexes) apexes.push_back({{"t", a.t}, {"height", a.height}});
    j["apexes"] = apexes;
    nlohmann::json floor = nlohmann::json::array();
    for (const ContactEvent& c : r.contact_events) {
        if (c.axis != dim - 1 || c.side > 0) continue;
        if (floor.size() == kReportedApexes) break;
        floor.push_back({{"t", c.t}, {"restitution", c.normal_coefficient}});
    }
    j["first_floor_contacts"] = floor;
    j["max_penetration"] = r.max_penetration;
    j["energy_max_rise"] = r.energy_max_rise;
    j["rest_time"] = r.rest_time ? nlohmann::json(*r.rest_time) : nlohmann::json(nullptr);
    j["final_state"] = {{"t", r.final_state.t},
                        {"position", vec_json(r.final_state.p, dim)},
                        {"velocity", vec_json(r.final_state.v, dim)}};
    j["run_seconds"] = r.run_seconds;
    j["ns_per_step"] = r.steps > 0 ? r.run_seconds * 1e9 / static_cast<double>(r.steps) : 0.0;
    if (!r.trajectory_file.empty()) j["trajectory"] = r.trajectory_file;
    if (!r.settings.empty()) {
        nlohmann::json settings = nlohmann::json::array();
        for (const auto& st : r.settings) settings.push_back({{"key", st.key}, {"value", st.value}, {"why", st.why}});
        j["settings"] = settings;
    }
    return j;
}

}  // namespace

nlohmann::json to_json(const RunReport& report) {
    nlohmann::json scenarios = nlohmann::json::array();
    for (const ScenarioRun& run : report.scenarios) {
        nlohmann::json results = nlohmann::json::array();
        for (const auto& r : run.results) results.push_back(result_json(r, run.scenario.dim));
        scenarios.push_back({{"scenario", scenario_json(run.scenario)}, {"simulators", results}});
    }
    return {{"schema", kReportSchema}, {"bouncecheck_version", BOUNCECHECK_VERSION}, {"scenarios", scenarios}};
}

void write_report_json(const RunReport& report, const std::filesystem::path& out_dir) {
    write_file_atomically(out_dir / "report.json", to_json(report).dump(2) + "\n");
}

std::string format_summary(const RunReport& report) {
    std::string text;
    auto out = std::back_inserter(text);
    for (const ScenarioRun& run : report.scenarios) {
        const Scenario& s = run.scenario;
        fmt::format_to(out, "\n{} ({}D, dt = {:g} s, duration = {:g} s)\n", s.name, s.dim, s.dt, s.duration);
        fmt::format_to(out, "  {:<10} {:>9} {:>9}  {:<31} {:>8} {:>10}\n", "simulator", "steps", "contacts",
                       "first apex heights (m)", "rest (s)", "run time");
        for (const SimulatorSummary& r : run.results) {
            if (r.status == RunStatus::skipped) {
                fmt::format_to(out, "  {:<10} skipped: {}\n", r.simulator, r.reason);
                continue;
            }
            std::string apexes;
            for (std::size_t i = 0; i < r.apexes.size() && i < 4; ++i)
                apexes += fmt::format("{}{:.4f}", i ? " " : "", r.apexes[i].height);
            const std::string contacts =
                fmt::format("{}{}", r.contacts, r.contacts_unbounded ? "+inf" : "");
            const std::string rest = r.rest_time ? fmt::format("{:.2f}", *r.rest_time) : "-";
            fmt::format_to(out, "  {:<10} {:>9} {:>9}  {:<31} {:>8} {:>8.3f}ms\n", r.simulator, r.steps, contacts,
                           apexes, rest, r.run_seconds * 1e3);
            if (r.status == RunStatus::failed) fmt::format_to(out, "  {:<10} FAILED: {}\n", "", r.reason);
        }
    }
    return text;
}

}  // namespace bouncecheck
