// report.html: report.json's content plus what the plots draw, inlined in one
// page with the charting library; sweep.html: sweep.json's, likewise. The page script (reports/html/page.js)
// builds every plot and table from that data; this file only prepares it.
#include "reports/run_report.h"
#include "reports/sweep_report.h"
#include "reports/web_assets.h"
#include "reports/json_number.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>

namespace bouncecheck {

namespace {

// Seven significant digits: plenty for a plot, and about half the bytes of a
// round-trip double. Non-finite values become null (a gap in the line).
nlohmann::json plot_number(double v) {
    if (!std::isfinite(v)) return nullptr;
    char buf[32];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 7);
    double rounded = v;
    std::from_chars(buf, end, rounded);
    return rounded;
}

nlohmann::json plot_numbers(const std::vector<double>& values) {
    nlohmann::json out = nlohmann::json::array();
    for (double v : values) out.push_back(plot_number(v));
    return out;
}

nlohmann::json path_json(const PlotTrace& trace, int dim) {
    nlohmann::json out = {{"t", plot_numbers(trace.t)}};
    const char* const names[] = {"x", "y", "z"};
    for (int axis = 0; axis < dim; ++axis) {
        nlohmann::json coordinate = nlohmann::json::array();
        for (const Vec3& p : trace.p) coordinate.push_back(plot_number(p[axis]));
        out[names[axis]] = std::move(coordinate);
    }
    return out;
}

// The vertical coordinate of the kept sample nearest to t (contacts are
// turning points, which the decimated trace keeps).
double height_at(const PlotTrace& trace, double t, int vertical) {
    if (trace.size() == 0) return std::nan("");
    const auto it = std::lower_bound(trace.t.begin(), trace.t.end(), t);
    std::size_t i = static_cast<std::size_t>(it - trace.t.begin());
    if (i == trace.size() || (i > 0 && t - trace.t[i - 1] < trace.t[i] - t)) --i;
    return trace.p[i][vertical];
}

constexpr std::size_t kPlottedContacts = 500;

std::string wall_name(int axis, int side) {
    static const char* const axes[] = {"x", "y", "z"};
    return fmt::format("{} {}", axes[axis], side < 0 ? "lower" : "upper");
}

nlohmann::json simulator_plot_json(const SimulatorSummary& r, const ScenarioRun::SimulatorPlot& plot,
                                   const Scenario& s) {
    const int vertical = s.vertical_axis();
    nlohmann::json contacts = {{"t", nlohmann::json::array()}, {"height", nlohmann::json::array()},
                               {"wall", nlohmann::json::array()}};
    for (std::size_t i = 0; i < r.contact_events.size() && i < kPlottedContacts; ++i) {
        const ContactEvent& e = r.contact_events[i];
        contacts["t"].push_back(plot_number(e.t));
        contacts["height"].push_back(plot_number(height_at(plot.path, e.t, vertical)));
        contacts["wall"].push_back(wall_name(e.axis, e.side));
    }
    nlohmann::json damping = {{"t", nlohmann::json::array()}, {"normal", nlohmann::json::array()},
                              {"tangential", nlohmann::json::array()}};
    const std::vector<ContactEvent> measured = damping_contacts(r, s);
    for (std::size_t i = 0; i < measured.size() && i < kPlottedContacts; ++i) {
        damping["t"].push_back(plot_number(measured[i].t));
        damping["normal"].push_back(plot_number(measured[i].normal_coefficient));
        damping["tangential"].push_back(plot_number(measured[i].tangential_retention));
    }
    return {
        {"name", r.simulator},
        {"status", to_string(r.status)},
        {"path", path_json(plot.path, s.dim)},
        {"contacts", contacts},
        {"damping", damping},
        {"divergence", {{"t", plot_numbers(plot.divergence_t)}, {"d", plot_numbers(plot.divergence)}}},
        {"error", {{"t", plot_numbers(plot.error_t)}, {"d", plot_numbers(plot.error)}}},
    };
}

nlohmann::json scenario_plots_json(const ScenarioRun& run) {
    const Scenario& s = run.scenario;
    nlohmann::json simulators = nlohmann::json::array();
    for (std::size_t i = 0; i < run.results.size(); ++i) {
        if (i < run.plots.size() && run.plots[i]) simulators.push_back(simulator_plot_json(run.results[i], *run.plots[i], s));
        else simulators.push_back(nullptr);
    }
    nlohmann::json apexes = {{"t", nlohmann::json::array()}, {"height", nlohmann::json::array()}};
    for (const Apex& a : run.exact_apexes) {
        apexes["t"].push_back(plot_number(a.t));
        apexes["height"].push_back(plot_number(a.height));
    }
    return {{"vertical", s.vertical_axis()}, {"exact_apexes", apexes}, {"simulators", simulators}};
}

}  // namespace

Page to_html(const RunReport& report) {
    nlohmann::json plots = nlohmann::json::array();
    for (const ScenarioRun& run : report.scenarios) plots.push_back(scenario_plots_json(run));
    const nlohmann::json data = {{"kind", "run"}, {"report", to_json(report)}, {"plots", plots}};
    return self_contained_page("bouncecheck report", json_text(data));
}

Page sweep_html(const nlohmann::json& sweep) {
    const nlohmann::json data = {{"kind", "sweep"}, {"sweep", sweep}};
    return self_contained_page("bouncecheck sweep: " + sweep.value("scenario", std::string()), json_text(data));
}

}  // namespace bouncecheck
