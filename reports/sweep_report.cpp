#include "reports/sweep_report.h"

#include "platform/atomic_file.h"
#include "reports/json_number.h"

#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <type_traits>

namespace bouncecheck {

namespace {

template <class T>
std::string csv_number(const std::optional<T>& v) {
    if (!v) return "";
    if constexpr (std::is_integral_v<T>) return fmt::format("{}", *v);
    else return fmt::format("{:.17g}", *v);
}

std::string table_number(const std::optional<double>& v, const char* spec) {
    return v ? fmt::format(fmt::runtime(spec), *v) : std::string("-");
}

}  // namespace

std::string sweep_csv(const SweepResult& r) {
    std::string out = "engine,dt,status,error,bounce_error,ns_per_step,sec_per_sim_sec,steps,outside_step_seconds\n";
    for (const SweepRow& row : r.rows)
        out += fmt::format("{},{:.17g},{},{},{},{},{},{},{}\n", row.engine, row.dt, to_string(row.status),
                           csv_number(row.error), csv_number(row.bounce_error), csv_number(row.ns_per_step),
                           csv_number(row.sec_per_sim_sec), csv_number(row.steps), csv_number(row.outside_step_seconds));
    return out;
}

void leave_out_timings(SweepResult& r) {
    for (SweepRow& row : r.rows) {
        row.ns_per_step.reset();
        row.sec_per_sim_sec.reset();
        row.min_seconds.reset();
        row.outside_step_seconds.reset();
    }
}

std::vector<bool> pareto_front(const std::vector<SweepRow>& rows) {
    const auto usable = [](const SweepRow& r) {
        return r.status == RunStatus::ok && r.error && *r.error > 0 && r.sec_per_sim_sec;
    };
    std::vector<bool> front(rows.size(), false);
    for (std::size_t i = 0; i < rows.size(); ++i) {
        if (!usable(rows[i])) continue;
        front[i] = std::none_of(rows.begin(), rows.end(), [&](const SweepRow& other) {
            if (!usable(other)) return false;
            const bool no_worse = *other.error <= *rows[i].error && *other.sec_per_sim_sec <= *rows[i].sec_per_sim_sec;
            const bool better = *other.error < *rows[i].error || *other.sec_per_sim_sec < *rows[i].sec_per_sim_sec;
            return no_worse && better;
        });
    }
    return front;
}

nlohmann::json sweep_json(const Scenario& s, const SweepResult& r, const nlohmann::json& parameters,
                          const nlohmann::json& provenance) {
    nlohmann::json rows = nlohmann::json::array();
    const std::vector<bool> front = pareto_front(r.rows);
    for (std::size_t i = 0; i < r.rows.size(); ++i) {
        const SweepRow& row = r.rows[i];
        nlohmann::json j{{"engine", row.engine},
                         {"dt", row.dt},
                         {"status", to_string(row.status)},
                         {"error", json_number(row.error)},
                         {"bounce_error", json_number(row.bounce_error)},
                         {"ns_per_step", json_number(row.ns_per_step)},
                         {"sec_per_sim_sec", json_number(row.sec_per_sim_sec)},
                         {"steps", json_number(row.steps)},
                         {"min_seconds", json_number(row.min_seconds)},
                         {"outside_step_seconds", json_number(row.outside_step_seconds)},
                         {"pareto", static_cast<bool>(front[i])}};
        if (!row.reason.empty()) j["reason"] = row.reason;
        rows.push_back(std::move(j));
    }
    nlohmann::json orders = nlohmann::json::array();
    for (const SweepOrder& o : r.orders)
        orders.push_back({{"engine", o.engine},
                          {"order", json_number(o.order)},
                          {"points", o.points},
                          {"caveat", order_caveat(o, r, s)}});
    nlohmann::json out = {{"schema", kSweepSchema},
            {"version", BOUNCECHECK_VERSION},
            {"scenario", s.name},
            {"dim", s.dim},
            {"duration", s.duration},
            {"error_metric", "trajectory RMS against exact before exact's rest (m)"},
            {"bounce_error_metric", "largest relative bounce height difference against exact"},
            {"parameters", parameters},
            {"rows", std::move(rows)},
            {"orders", std::move(orders)}};
    if (!provenance.is_null()) out["provenance"] = provenance;
    return out;
}

std::string order_caveat(const SweepOrder& o, const SweepResult& r, const Scenario& s) {
    if (!o.order) return "";
    double largest = 0;
    for (const SweepRow& row : r.rows)
        if (row.engine == o.engine && row.status == RunStatus::ok && row.error) largest = std::max(largest, *row.error);
    const double room = s.room.head(s.dim).maxCoeff();
    if (largest < 1e-9 * room)
        return fmt::format("not an order: every error is round-off (largest {:.2g} m)", largest);
    const auto table = s.engines.find(o.engine);
    const bool tangential_motion = s.velocity.head(s.dim - 1).norm() > 0 || s.gravity.head(s.dim - 1).norm() > 0;
    if (table != s.engines.end() && table->second.tangential_model == TangentialModel::friction && tangential_motion)
        return "not the law's order: friction mode converges to Coulomb friction, not to beta";
    return "";
}

std::string format_sweep(const Scenario& s, const SweepResult& r) {
    std::string out = fmt::format(
        "\n{}: work-precision sweep (error: trajectory RMS against exact before its rest; "
        "timing: fastest of the timed runs)\n",
        s.name);
    out += fmt::format("  {:<10} {:>11} {:>11} {:>11} {:>10}  {}\n", "engine", "dt", "error (m)", "bounce err",
                       "ns/step", "status");
    for (const SweepOrder& o : r.orders) {
        for (const SweepRow& row : r.rows) {
            if (row.engine != o.engine) continue;
            std::string status = to_string(row.status);
            if (!row.reason.empty()) status += ": " + row.reason;
            out += fmt::format("  {:<10} {:>11.6g} {:>11} {:>11} {:>10}  {}\n", row.engine, row.dt,
                               table_number(row.error, "{:.4e}"), table_number(row.bounce_error, "{:.4e}"),
                               table_number(row.ns_per_step, "{:.1f}"), status);
        }
        const std::string caveat = order_caveat(o, r, s);
        if (o.order)
            out += fmt::format("  {:<10} observed order {:.3f} (least squares over {} points){}\n", o.engine,
                               *o.order, o.points, caveat.empty() ? "" : ": " + caveat);
        else
            out += fmt::format("  {:<10} observed order: not enough points ({} with error > 0)\n", o.engine, o.points);
    }
    return out;
}

WrittenFiles write_sweep(const Scenario& s, const SweepResult& r, const nlohmann::json& parameters,
                 const std::filesystem::path& out_dir, const nlohmann::json& provenance) {
    OutputWrites writes;  // one file that cannot be written costs only itself
    writes.attempt([&] { write_file_atomically(out_dir / "sweep.csv", sweep_csv(r)); });
    const nlohmann::json json = sweep_json(s, r, parameters, provenance);
    writes.attempt([&] { write_file_atomically(out_dir / "sweep.json", json_text(json, 2) + "\n"); });
    writes.attempt([&] { write_page(out_dir / "sweep.html", sweep_html(json)); });
    writes.finish();
    return {"sweep.csv", "sweep.json", "sweep.html"};
}

}  // namespace bouncecheck
