#include "commands/run/run_pipeline.h"

#include "commands/command.h"
#include "commands/wire.h"
#include "exact/exact_simulator.h"
#include "metrics/summary.h"
#include "platform/parallel_pairs.h"
#include "reference/reference_simulator.h"
#include "reports/trajectory_csv.h"

#include <fmt/format.h>

#include <algorithm>
#include <exception>
#include <optional>
#include <string>
#include <vector>

namespace bouncecheck {

namespace {

// ------------------------------------------------ the outcome across a worker's channel (commands/wire.h)

using nlohmann::json;

json encode(const TrajectoryDivergence& d) {
    return json::array({d.samples, d.rms, d.max, wire::optional(d.rest_cut), d.rms_before_rest, d.max_before_rest,
                        d.tolerance, wire::optional(d.first_exceeds)});
}
TrajectoryDivergence decode_divergence(const json& j) {
    return TrajectoryDivergence{j[0].get<std::int64_t>(),          j[1].get<double>(), j[2].get<double>(),
                                wire::optional_from<double>(j[3]), j[4].get<double>(), j[5].get<double>(),
                                j[6].get<double>(),                wire::optional_from<double>(j[7])};
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

std::string encode(const ComparedRun& o) {
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
        {"energy", r.energy_max_rise}, {"rest", wire::optional(r.rest_time)}, {"final_t", r.final_state.t},
        {"filled", {wire::optional(r.filled_from), r.fill_period, r.fill_steps}},
        {"final", encode(std::vector<Vec3>{r.final_state.p, r.final_state.v})}, {"settings", settings},
        {"seconds", r.run_seconds}, {"step_seconds", wire::optional(r.step_seconds)}, {"trajectory", r.trajectory_file},
        {"vs_reference", encode(o.vs_reference)}, {"vs_exact", encode(o.vs_exact)}, {"plot", nullptr},
    };
    if (o.plot) {
        j["plot"] = {{"t", o.plot->path.t}, {"p", encode(o.plot->path.p)}, {"divergence_t", o.plot->divergence_t},
                     {"divergence", o.plot->divergence}, {"error_t", o.plot->error_t}, {"error", o.plot->error}};
    }
    return wire::to_bytes(j);
}

ComparedRun decode(const std::string& bytes) {
    const json j = wire::from_bytes(bytes);
    ComparedRun o;
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
    r.rest_time = wire::optional_from<double>(j["rest"]);
    r.filled_from = wire::optional_from<double>(j["filled"][0]);
    r.fill_period = j["filled"][1].get<std::int64_t>();
    r.fill_steps = j["filled"][2].get<std::int64_t>();
    const std::vector<Vec3> final_state = decode_points(j["final"]);
    r.final_state = State{j["final_t"].get<double>(), final_state.at(0), final_state.at(1)};
    for (const json& st : j["settings"])
        r.settings.push_back({st[0].get<std::string>(), st[1].get<std::string>(), st[2].get<std::string>()});
    r.run_seconds = j["seconds"].get<double>();
    r.step_seconds = wire::optional_from<double>(j["step_seconds"]);
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

// The engines (Simulator::third_party) in worker processes, when the
// request isolates them: a crash or a hang there is that engine's failure
// only. An engine that runs in a program of its own is isolated already,
// and stays here unless a budget is given: the workers' deadline enforces it. Their outcomes in the simulators' order; nothing where a simulator
// runs here (not an engine, not isolated, or it cannot run the scenario).
std::vector<std::optional<ComparedRun>> run_isolated(const Scenario& s, const RunRequest& request,
                                                 const Baselines& base) {
    const std::vector<const Simulator*>& sims = request.simulators;
    std::vector<std::optional<ComparedRun>> outcomes(sims.size());
    std::vector<std::size_t> pooled;
    for (std::size_t i = 0; i < sims.size(); ++i)
        if (request.isolate && sims[i]->third_party() && !sims[i]->cannot_run(s) &&
            (!sims[i]->runs_in_own_program() || request.budget_seconds > 0))
            pooled.push_back(i);
    PairSchedule schedule;
    schedule.jobs = request.jobs;
    schedule.deadline_seconds = request.budget_seconds;
    schedule.cost = [&](std::size_t k, std::size_t) { return sims[pooled[k]]->typical_ns_per_step(); };
    schedule.run = [&](std::size_t k, std::size_t) { return encode(run_compared(*sims[pooled[k]], s, request, base)); };
    schedule.finished = [&](std::size_t k, std::size_t, const PairOutcome& ended, std::size_t, std::size_t) {
        ComparedRun o;
        if (const auto failure = decode_pair(ended, [&](const std::string& payload) { o = decode(payload); })) {
            o = ComparedRun{};
            o.summary.simulator = std::string(sims[pooled[k]]->name());
            o.summary.status = RunStatus::failed;
            o.summary.reason = failure->labelled();
            if (request.plots) o.plot.emplace();
        }
        outcomes[pooled[k]] = std::move(o);
    };
    run_pairs_in_parallel(pooled.size(), 1, schedule);
    return outcomes;
}

}  // namespace

// ------------------------------------------------ one simulator

namespace {

// The reference runs once per scenario, as the baseline; its own row is that
// run, compared as it streams (Baselines).
bool is_the_reference(const Simulator& sim) { return sim.name() == "reference"; }

}  // namespace

Baselines::Baselines(const Scenario& s, const RunRequest& request)
    : exact(s), exact_summary(record_run(*make_exact_simulator(), s)) {
    if (request.plots) exact_path = exact_plot_trace(exact, s);
    const Simulator* reference_sim = nullptr;
    std::size_t readers = 0;
    for (const Simulator* sim : request.simulators) {
        if (is_the_reference(*sim)) reference_sim = sim;
        else if (!sim->cannot_run(s)) ++readers;
    }
    if (readers >= 2) track = TrajectoryComparer::share_baselines(s, exact);
    if (reference_sim) {
        reference_row = run_compared(*reference_sim, s, request, *this);
        reference = reference_row->summary;
    } else {
        reference = record_run(*make_reference_simulator(), s);
    }
}

namespace {

// Every state to the comparison, and to the plot and the trajectory file
// when asked: direct calls to final classes, a block at a time each.
struct ComparedSink final : StateSink {
    TrajectoryComparer& comparer;
    TraceDecimator* trace;
    TrajectoryCsv* csv;
    ComparedSink(TrajectoryComparer& c, TraceDecimator* t, TrajectoryCsv* f) : comparer(c), trace(t), csv(f) {}
    void write(const State& s) override { write_block({&s, 1}); }
    void write_block(std::span<const State> states) override {
        comparer.write_block(states);
        if (trace) trace->write_block(states);
        if (csv) csv->write_block(states);
    }
    void write_periodic(const PeriodicTail& tail) override {
        comparer.write_periodic(tail);
        if (trace) trace->write_periodic(tail);
        if (csv) csv->write_periodic(tail);
    }
};

}  // namespace

ComparedRun run_compared(const Simulator& sim, const Scenario& s, const RunRequest& request, const Baselines& base) {
    ComparedRun o;
    o.summary.simulator = std::string(sim.name());
    // The reference's own row is run while its baselines are made
    // (Baselines), before base.reference exists.
    const bool is_reference = is_the_reference(sim);
    TrajectoryComparer comparer =
        is_reference ? TrajectoryComparer::of_the_reference(s, base.exact, base.exact_summary.rest_time, base.track)
                     : TrajectoryComparer(s, base.exact, base.reference.rest_time, base.exact_summary.rest_time,
                                          base.track);
    std::optional<TraceDecimator> trace;
    const std::int64_t states = expected_states(s);
    if (request.plots) {
        // exact's own samples sit on the document clock; its plotted path is
        // the one with the contacts at their instants (Baselines::exact_path).
        if (sim.name() != "exact") trace.emplace(states, s.dim);
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
        ComparedSink sink(comparer, trace ? &*trace : nullptr, csv ? &*csv : nullptr);
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
    if (is_reference) o.vs_reference.rest_cut = o.summary.rest_time;  // its own rest is the reference's
    o.vs_exact = comparer.vs_exact();
    if (request.plots) {
        ScenarioRun::SimulatorPlot plot;
        plot.path = trace ? trace->finish() : base.exact_path;
        DistanceSeries divergence = *comparer.reference_series(), error = *comparer.exact_series();
        plot.divergence_t = std::move(divergence.t);
        plot.divergence = std::move(divergence.distance);
        plot.error_t = std::move(error.t);
        plot.error = std::move(error.distance);
        o.plot = std::move(plot);
    }
    return o;
}

int run_exit_status(const RunVerdict& v) {
    if (!v.failed.empty()) return kSimulatorFailed;
    return !v.exceeded.empty() || v.baseline_changed ? kThresholdExceeded : kOk;
}

ScenarioRun run_scenario(const Scenario& s, const RunRequest& request) {
    ScenarioRun run;
    run.scenario = s;
    const Baselines base(s, request);
    if (request.plots) {
        run.exact_path = base.exact_path;
        run.exact_apexes = base.exact_summary.apexes;
    }
    std::vector<std::optional<ComparedRun>> isolated = run_isolated(s, request, base);

    for (std::size_t i = 0; i < request.simulators.size(); ++i) {
        const Simulator* sim = request.simulators[i];
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
        ComparedRun o = isolated[i]              ? std::move(*isolated[i])
                        : is_the_reference(*sim) ? *base.reference_row
                                                 : run_compared(*sim, s, request, base);
        o.summary.origin = std::string(sim->origin());
        const ThresholdSet limits = limits_for(s, o.summary.simulator, request.threshold_overrides);
        const int bounce_count = limits.bounce_count.value_or(kDefaultBounceCount);
        Comparison c;
        c.vs_reference = compare_bounces(o.summary, base.reference, bounce_count, s);
        c.vs_reference.trajectory = o.vs_reference;
        c.vs_exact = compare_bounces(o.summary, base.exact_summary, bounce_count, s);
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
