#include "commands/run/run_pipeline.h"

#include "exact/exact_simulator.h"
#include "metrics/summary.h"
#include "platform/isolation.h"
#include "reference/reference_simulator.h"
#include "reports/trajectory_csv.h"

#include <fmt/format.h>

#include <algorithm>
#include <optional>

namespace bouncecheck {

namespace {

// What one simulator's run produces before it is judged: the comparison's
// verdicts follow from it and the baselines (see run_scenario).
struct Outcome {
    SimulatorSummary summary;
    TrajectoryDivergence vs_reference, vs_exact;
    std::optional<ScenarioRun::SimulatorPlot> plot;
};

// ------------------------------------------------ the outcome across a pipe (CBOR keeps every double's bits)

using nlohmann::json;

json opt(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }
std::optional<double> opt(const json& j) { return j.is_null() ? std::nullopt : std::optional<double>(j.get<double>()); }

json encode(const TrajectoryDivergence& d) {
    return json::array({d.samples, d.rms, d.max, opt(d.rest_cut), d.rms_before_rest, d.max_before_rest, d.tolerance,
                        opt(d.first_exceeds)});
}
TrajectoryDivergence decode_divergence(const json& j) {
    return TrajectoryDivergence{j[0].get<std::int64_t>(), j[1].get<double>(), j[2].get<double>(), opt(j[3]),
                                j[4].get<double>(),       j[5].get<double>(), j[6].get<double>(), opt(j[7])};
}

json encode(const std::vector<Vec3>& points) {
    json out = json::array();
    for (const Vec3& p : points) out.insert(out.end(), {p.x(), p.y(), p.z()});
    return out;
}
std::vector<Vec3> decode_points(const json& j) {
    std::vector<Vec3> out;
    for (std::size_t i = 0; i + 2 < j.size(); i += 3)
        out.emplace_back(j[i].get<double>(), j[i + 1].get<double>(), j[i + 2].get<double>());
    return out;
}

std::string encode(const Outcome& o) {
    const SimulatorSummary& r = o.summary;
    json apexes = json::array(), contacts = json::array(), settings = json::array();
    for (const Apex& a : r.apexes) apexes.push_back({a.t, a.height});
    for (const ContactEvent& c : r.contact_events)
        contacts.push_back({c.t, c.axis, c.side, c.normal_coefficient, c.tangential_retention, c.normal_speed_in});
    for (const auto& st : r.settings) settings.push_back({st.key, st.value, st.why});
    json j = {
        {"simulator", r.simulator}, {"status", static_cast<int>(r.status)}, {"reason", r.reason},
        {"counts", {r.steps, r.contacts, r.floor_contacts, r.apex_count}}, {"unbounded", r.contacts_unbounded},
        {"apexes", apexes}, {"contacts", contacts}, {"penetration", r.max_penetration},
        {"energy", r.energy_max_rise}, {"rest", opt(r.rest_time)}, {"final_t", r.final_state.t},
        {"filled", {opt(r.filled_from), r.fill_period, r.fill_steps}},
        {"final", encode(std::vector<Vec3>{r.final_state.p, r.final_state.v})}, {"settings", settings},
        {"seconds", r.run_seconds}, {"trajectory", r.trajectory_file},
        {"vs_reference", encode(o.vs_reference)}, {"vs_exact", encode(o.vs_exact)}, {"plot", nullptr},
    };
    if (o.plot) {
        j["plot"] = {{"t", o.plot->path.t}, {"p", encode(o.plot->path.p)}, {"divergence_t", o.plot->divergence_t},
                     {"divergence", o.plot->divergence}, {"error_t", o.plot->error_t}, {"error", o.plot->error}};
    }
    const std::vector<std::uint8_t> bytes = json::to_cbor(j);
    return std::string(bytes.begin(), bytes.end());
}

Outcome decode(const std::string& bytes) {
    const json j = json::from_cbor(bytes);
    Outcome o;
    SimulatorSummary& r = o.summary;
    r.simulator = j["simulator"].get<std::string>();
    r.status = static_cast<RunStatus>(j["status"].get<int>());
    r.reason = j["reason"].get<std::string>();
    r.steps = j["counts"][0].get<std::int64_t>();
    r.contacts = j["counts"][1].get<std::int64_t>();
    r.floor_contacts = j["counts"][2].get<std::int64_t>();
    r.apex_count = j["counts"][3].get<std::int64_t>();
    r.contacts_unbounded = j["unbounded"].get<bool>();
    for (const json& a : j["apexes"]) r.apexes.push_back(Apex{a[0].get<double>(), a[1].get<double>()});
    for (const json& c : j["contacts"])
        r.contact_events.push_back(ContactEvent{c[0].get<double>(), c[1].get<int>(), c[2].get<int>(),
                                                c[3].get<double>(), c[4].get<double>(), c[5].get<double>()});
    r.max_penetration = j["penetration"].get<double>();
    r.energy_max_rise = j["energy"].get<double>();
    r.rest_time = opt(j["rest"]);
    r.filled_from = opt(j["filled"][0]);
    r.fill_period = j["filled"][1].get<std::int64_t>();
    r.fill_steps = j["filled"][2].get<std::int64_t>();
    const std::vector<Vec3> final_state = decode_points(j["final"]);
    r.final_state = State{j["final_t"].get<double>(), final_state.at(0), final_state.at(1)};
    for (const json& st : j["settings"])
        r.settings.push_back({st[0].get<std::string>(), st[1].get<std::string>(), st[2].get<std::string>()});
    r.run_seconds = j["seconds"].get<double>();
    r.trajectory_file = j["trajectory"].get<std::string>();
    o.vs_reference = decode_divergence(j["vs_reference"]);
    o.vs_exact = decode_divergence(j["vs_exact"]);
    if (!j["plot"].is_null()) {
        const json& p = j["plot"];
        o.plot.emplace();
        o.plot->path.t = p["t"].get<std::vector<double>>();
        o.plot->path.p = decode_points(p["p"]);
        o.plot->divergence_t = p["divergence_t"].get<std::vector<double>>();
        o.plot->divergence = p["divergence"].get<std::vector<double>>();
        o.plot->error_t = p["error_t"].get<std::vector<double>>();
        o.plot->error = p["error"].get<std::vector<double>>();
    }
    return o;
}

// ------------------------------------------------ one simulator

struct Baselines {
    const ExactModel& exact;
    const SimulatorSummary& reference;
    const SimulatorSummary& exact_summary;
    const PlotTrace& exact_path;
};

// Runs `sim` with its stream compared to the baselines as it goes, writing
// its trajectory if asked; an exception is a failed run.
Outcome run_one(const Simulator& sim, const Scenario& s, const RunRequest& request, const Baselines& base) {
    Outcome o;
    o.summary.simulator = std::string(sim.name());
    TrajectoryComparer comparer(s, base.exact, base.reference.rest_time, base.exact_summary.rest_time);
    std::optional<TraceDecimator> trace;
    const std::int64_t states = expected_states(s);
    if (request.plots) {
        // exact's own samples sit on the document clock; its plotted path is
        // the one with the contacts at their instants (Baselines::exact_path).
        if (sim.name() != "exact") trace.emplace(states);
        comparer.record_series(plot_stride(states));
    }
    try {
        std::optional<TrajectoryCsv> csv;
        std::filesystem::path relative;
        if (request.trajectories) {
            relative = std::filesystem::path(s.name) / (o.summary.simulator + ".csv");
            std::filesystem::create_directories(request.out_dir / s.name);
            csv.emplace(request.out_dir / relative, s.dim);
        }
        TeeSink sink{csv ? &*csv : nullptr, &comparer, trace ? &*trace : nullptr};
        o.summary = record_run(sim, s, &sink);
        if (csv) {
            csv->commit();
            o.summary.trajectory_file = relative.string();
        }
    } catch (const std::exception& e) {
        o.summary.status = RunStatus::failed;
        o.summary.reason = fmt::format("exception: {}", e.what());
    }
    o.vs_reference = comparer.vs_reference();
    o.vs_exact = comparer.vs_exact();
    if (request.plots) {
        ScenarioRun::SimulatorPlot plot;
        plot.path = trace ? trace->finish() : base.exact_path;
        plot.divergence_t = comparer.reference_series()->times();
        plot.divergence = comparer.reference_series()->values();
        plot.error_t = comparer.exact_series()->times();
        plot.error = comparer.exact_series()->values();
        o.plot = std::move(plot);
    }
    return o;
}

// run_one in a child process: a crash there is this simulator's failure only.
Outcome run_one_isolated(const Simulator& sim, const Scenario& s, const RunRequest& request, const Baselines& base) {
    const ChildResult child = run_in_child([&] { return encode(run_one(sim, s, request, base)); });
    if (child.ok) {
        try {
            return decode(child.payload);
        } catch (const std::exception& e) {
            Outcome o;
            o.summary.simulator = std::string(sim.name());
            o.summary.status = RunStatus::failed;
            o.summary.reason = fmt::format("its child process sent an unreadable result: {}", e.what());
            return o;
        }
    }
    Outcome o;
    o.summary.simulator = std::string(sim.name());
    o.summary.status = RunStatus::failed;
    o.summary.reason = child.failure;
    if (request.plots) o.plot.emplace();
    return o;
}

}  // namespace

ScenarioRun run_scenario(const Scenario& s, const RunRequest& request) {
    ScenarioRun run;
    run.scenario = s;
    const ExactModel exact(s);
    const SimulatorSummary reference = record_run(*make_reference_simulator(), s);
    const SimulatorSummary exact_summary = record_run(*make_exact_simulator(), s);
    if (request.plots) {
        run.exact_path = exact_plot_trace(exact, s);
        run.exact_apexes = exact_summary.apexes;
    }
    const Baselines base{exact, reference, exact_summary, run.exact_path};

    for (const Simulator* sim : request.simulators) {
        if (auto why = sim->cannot_run(s)) {
            SimulatorSummary skipped;
            skipped.simulator = std::string(sim->name());
            skipped.origin = std::string(sim->origin());
            skipped.status = RunStatus::skipped;
            skipped.reason = *why;
            run.results.push_back(skipped);
            run.comparisons.emplace_back();
            if (request.plots) run.plots.emplace_back();
            continue;
        }
        Outcome o = request.isolate && sim->third_party() ? run_one_isolated(*sim, s, request, base)
                                                          : run_one(*sim, s, request, base);
        o.summary.origin = std::string(sim->origin());
        const ThresholdSet limits = limits_for(s, o.summary.simulator, request.threshold_overrides);
        const int bounce_count = limits.bounce_count.value_or(kDefaultBounceCount);
        Comparison c;
        c.vs_reference = compare_bounces(o.summary, reference, bounce_count, s);
        c.vs_reference.trajectory = o.vs_reference;
        c.vs_exact = compare_bounces(o.summary, exact_summary, bounce_count, s);
        c.vs_exact.trajectory = o.vs_exact;
        c.damping = check_damping(o.summary, s, limits);
        c.thresholds = check_thresholds(c, limits, s);
        if (request.plots) run.plots.push_back(std::move(o.plot));
        run.results.push_back(std::move(o.summary));
        run.comparisons.push_back(std::move(c));
    }
    return run;
}

}  // namespace bouncecheck
