// `bouncecheck sweep`: the work-precision sweep of one scenario over a series of dt.
#include "commands/command.h"
#include "platform/printable_text.h"

#include "commands/shards.h"
#include "commands/sweep/sweep_pipeline.h"
#include "registry/registry.h"
#include "reports/provenance.h"
#include "scenarios/loader.h"
#include "scenarios/scenario_toml.h"
#include "reports/json_number.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

struct SweepOptions {
    std::string file;
    std::vector<std::string> engines;
    bool no_timings = false;  // an output choice: not in the shard's options
    std::string dt;
    int repeat = 3;
    int jobs = 0;  // 0: every core
    double budget = 0;  // s per pair; 0: no limit
    std::string out_dir = "bouncecheck-out";
    ExternalOptions external;
    std::string shard;  // K/N, or empty: the whole sweep
};

// What a shard hands merge to plan the same sweep (all but --out and --shard).
nlohmann::json to_json(const SweepOptions& o) {
    return {{"file", o.file},
            {"engines", o.engines},
            {"dt", o.dt},
            {"repeat", o.repeat},
            {"jobs", o.jobs},
            {"budget", o.budget},
            {"external", to_json(o.external)}};
}

SweepOptions sweep_options_from(const nlohmann::json& j) {
    SweepOptions o;
    o.file = j.at("file").get<std::string>();
    o.engines = j.at("engines").get<std::vector<std::string>>();
    o.dt = j.at("dt").get<std::string>();
    o.repeat = j.at("repeat").get<int>();
    o.jobs = j.at("jobs").get<int>();
    o.budget = j.at("budget").get<double>();
    o.external = external_options_from(j.at("external"));
    return o;
}

// The sweep the options describe: its scenario, time steps and simulators, before anything runs.
struct SweepPlan {
    ExtraSimulators extra;
    std::vector<std::unique_ptr<const Simulator>> built;
    Scenario scenario;
    std::vector<double> dts;
    std::vector<const Simulator*> simulators;

    // sweep.json's "parameters".
    nlohmann::json parameters(const SweepOptions& opt, const fs::path& out_dir) const {
        return {{"scenario_file", opt.file},
                {"engines", simulator_names(simulators)},
                {"origins", simulator_origins(simulators)},
                {"dt", dts},
                {"dt_source", opt.dt.empty() ? "default" : "--dt"},
                {"dt_argument", opt.dt},
                {"repeat", opt.repeat},
                {"jobs", opt.jobs > 0 ? opt.jobs : 0},
                {"budget_seconds", opt.budget},
                {"out", out_dir.string()}};
    }
    // Everything that decides the sweep's results: shards and merge compare it.
    std::string fingerprint(const SweepOptions& opt) const {
        nlohmann::json options = to_json(opt);
        options.erase("jobs");
        return run_fingerprint("sweep", json_text(options) + "\n" + json_text(parameters(opt, {})) + "\n" +
                                            scenario_toml(scenario));
    }
};

std::optional<SweepPlan> plan_sweep(const SweepOptions& opt) {
    // A program silent for longer than its pair's whole budget has hung.
    ExternalOptions external = opt.external;
    if (opt.budget > 0) external.timeout_seconds = std::min(external.timeout_seconds, opt.budget);
    if (opt.budget > 0) external.total_seconds = opt.budget;  // and one still talking at its end is stopped there
    auto extra = ExtraSimulators::from_options(external);
    if (!extra) return std::nullopt;
    auto scenarios = load_all({opt.file}, extra->command_line_names());
    if (!scenarios || !extra->admit_scenario_programs(*scenarios)) return std::nullopt;
    const Scenario& s = scenarios->front();

    std::vector<double> dts;
    if (opt.dt.empty()) {
        dts = default_sweep_dts(s.dt);
    } else {
        DtParse parsed = parse_dt_list(opt.dt);
        if (!parsed.error.empty()) {
            fmt::print(stderr, "error: --dt {}\n", parsed.error);
            return std::nullopt;
        }
        dts = std::move(parsed.dts);
    }
    for (double dt : dts) {
        if (dt > s.duration) {
            fmt::print(stderr, "error: --dt {}: larger than the scenario's duration {}\n", dt, s.duration);
            return std::nullopt;
        }
        if (dt < kMinDt) {
            fmt::print(stderr, "error: --dt {}: below the smallest time step, {:g} s\n", dt, kMinDt);
            return std::nullopt;
        }
        if (s.duration / dt > kMaxSteps) {
            fmt::print(stderr, "error: --dt {}: more than {:.0e} steps over {} s\n", dt, kMaxSteps, s.duration);
            return std::nullopt;
        }
    }

    SweepPlan plan{std::move(*extra), built_simulators(external.limits()), s, std::move(dts), {}};
    // exact is the truth every error is measured against: never swept.
    const auto selected =
        select_simulators(plan.built, opt.engines, "exact", "exact is the truth the sweep measures against");
    if (!selected) return std::nullopt;
    plan.simulators = plan.extra.for_scenario(plan.scenario, *selected);
    return plan;
}

// The table on the terminal, and sweep.csv, sweep.json and sweep.html in `out_dir`.
// `written`: what the command wrote before (a shard's file).
int report_sweep(SweepResult result, const SweepPlan& plan, OutputFolder& out, const nlohmann::json& parameters,
                 double wall_seconds, bool no_timings, WrittenFiles written = {}) {
    if (no_timings) leave_out_timings(result);
    fmt::print("{}", format_sweep(plan.scenario, result));
    for (std::string& file : write_sweep(plan.scenario, result, parameters, out.dir(),
                                         to_json(this_provenance(/*with_machine=*/!no_timings))))
        written.push_back(std::move(file));
    fmt::print("\nwrote sweep.csv, sweep.json and sweep.html in {}{}\n", out.dir().string(),
               no_timings ? "" : fmt::format(" ({:.2f} s)", wall_seconds));
    record_outputs(out, "sweep", written);
    const bool any_failed = std::any_of(result.rows.begin(), result.rows.end(),
                                        [](const SweepRow& r) { return r.status == RunStatus::failed; });
    return any_failed ? kSimulatorFailed : kOk;
}

int command_sweep(const SweepOptions& opt) {
    const auto plan = plan_sweep(opt);
    if (!plan) return kBadInput;
    const fs::path out_dir = opt.out_dir;
    auto out = OutputFolder::open(out_dir);
    if (!out) return kBadInput;

    SweepRequest request;
    request.simulators = plan->simulators;
    request.dts = plan->dts;
    request.repeat = opt.repeat;
    request.jobs = opt.jobs;
    request.budget_seconds = opt.budget;
    request.shard = shard_of(opt.shard);
    request.on_progress = [](const SweepRow& row, std::size_t done, std::size_t total) {
        if (row.status == RunStatus::ok)
            fmt::print(stderr, "[{}/{}] {} dt={:.6g}: error {:.4e} m, {:.1f} ns/step\n", done, total, row.engine, row.dt,
                       *row.error, row.ns_per_step.value_or(0.0));
        else
            fmt::print(stderr, "[{}/{}] {} dt={:.6g}: {}: {}\n", done, total, row.engine, row.dt,
                       to_string(row.status), row.reason);
    };
    const auto wall_start = std::chrono::steady_clock::now();
    const SweepResult result = run_sweep(plan->scenario, request);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    nlohmann::json parameters = plan->parameters(opt, out_dir);
    if (!request.shard.whole()) {
        // The shard's own rows as files, and what merge needs to put them back.
        parameters["shard"] = opt.shard;
        ShardFile file{"sweep", request.shard, plan->dts.size() * plan->simulators.size(), plan->fingerprint(opt),
                       to_json(opt), wall, result.slots, {}};
        for (const SweepRow& row : result.rows) file.results.push_back(encode_sweep_row(row));
        return report_sweep(result, *plan, *out, parameters, wall, opt.no_timings, write_shard_file(out_dir, file));
    }
    return report_sweep(result, *plan, *out, parameters, wall, opt.no_timings);
}

}  // namespace

int merge_sweep(const ShardSet& shards, OutputFolder& out, bool no_timings) {
    SweepOptions opt;
    try {
        opt = sweep_options_from(shards.options);
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: the shards' sweep options are unreadable: {}\n", error_text(e));
        return kBadInput;
    }
    const auto plan = plan_sweep(opt);
    if (!plan) return kBadInput;
    if (!shards_ran_this_plan(shards, plan->fingerprint(opt))) return kBadInput;
    SweepResult result;
    try {
        result = sweep_result_from_rows(simulator_names(plan->simulators), plan->dts, shards.results);
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: a shard's row is unreadable: {}\n", error_text(e));
        return kBadInput;
    }
    return report_sweep(std::move(result), *plan, out, plan->parameters(opt, out.dir()), shards.wall_seconds,
                        no_timings);
}

Command add_sweep_command(CLI::App& app) {
    auto opt = std::make_shared<SweepOptions>();
    CLI::App* command = app.add_subcommand(
        "sweep", "Work-precision sweep: each simulator's error against exact and cost per step over a series of dt");
    command->add_option("scenario", opt->file, "Scenario file")->required();
    add_list_option(*command, "--engines", opt->engines, "Simulators (default: every one built but exact, the truth)");
    command->add_option("--dt", opt->dt,
                        "Time steps: a list 0.03,0.015,... or FROM:TO:FACTOR (FROM, FROM/FACTOR, ... while >= TO). "
                        "Default: the scenario's dt halved down to max(1e-5, dt/2^7), capped to keep a run quick");
    command->add_option("--repeat", opt->repeat, "Timed runs per (simulator, dt); the fastest is kept")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000));
    command->add_option("--jobs", opt->jobs,
                        "(simulator, dt) pairs run at once, each in a worker process (default: every core)")
        ->check(CLI::Range(1, 4096));
    command->add_option("--budget", opt->budget,
                        "Wall-time limit of one (simulator, dt) pair, its timed runs included (s): past it the pair "
                        "is killed and fails as hung (default: no limit)")
        ->check(finite_between(0.001, 1e7));
    command->add_option("--out", opt->out_dir, "Output folder for sweep.csv, sweep.json and sweep.html")->capture_default_str();
    add_no_timings_flag(*command, opt->no_timings);
    add_shard_option(*command, opt->shard);
    add_external_options(*command, opt->external);
    add_scenario_programs_flag(*command, opt->external);
    set_exit_status_help(*command, {{kOk, "every (simulator, dt) pair ran or was skipped"},
                                   {kBadInput, "bad input or usage: nothing was run"},
                                   {kSimulatorFailed, "a pair failed, crashed or hung: the other rows are still written"}});
    return {command, [opt] { return command_sweep(*opt); }};
}

}  // namespace bouncecheck
