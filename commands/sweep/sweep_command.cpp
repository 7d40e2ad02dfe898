// `bouncecheck sweep`: the work-precision sweep of one scenario over a series of dt.
#include "commands/command.h"

#include "commands/sweep/sweep_pipeline.h"
#include "registry/registry.h"
#include "reports/provenance.h"
#include "scenarios/loader.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

struct SweepOptions {
    std::string file;
    std::string engines;
    std::string dt;
    int repeat = 3;
    int jobs = 0;  // 0: every core
    double budget = 0;  // s per pair; 0: no limit
    std::string out_dir = "bouncecheck-out";
    ExternalOptions external;
};

int command_sweep(const SweepOptions& opt) {
    // A program silent for longer than its pair's whole budget has hung.
    ExternalOptions external = opt.external;
    if (opt.budget > 0) external.timeout_seconds = std::min(external.timeout_seconds, opt.budget);
    auto extra = ExtraSimulators::from_options(external);
    if (!extra) return kBadInput;
    auto scenarios = load_all({opt.file}, extra->command_line_names());
    if (!scenarios) return kBadInput;
    const Scenario& s = scenarios->front();

    std::vector<double> dts;
    if (opt.dt.empty()) {
        dts = default_sweep_dts(s.dt);
    } else {
        DtParse parsed = parse_dt_list(opt.dt);
        if (!parsed.error.empty()) {
            fmt::print(stderr, "error: --dt {}\n", parsed.error);
            return kBadInput;
        }
        dts = std::move(parsed.dts);
    }
    for (double dt : dts) {
        if (dt > s.duration) {
            fmt::print(stderr, "error: --dt {}: larger than the scenario's duration {}\n", dt, s.duration);
            return kBadInput;
        }
        if (dt < kMinDt) {
            fmt::print(stderr, "error: --dt {}: below the smallest time step, {:g} s\n", dt, kMinDt);
            return kBadInput;
        }
        if (s.duration / dt > kMaxSteps) {
            fmt::print(stderr, "error: --dt {}: more than {:.0e} steps over {} s\n", dt, kMaxSteps, s.duration);
            return kBadInput;
        }
    }

    // exact is the truth every error is measured against: never swept.
    const auto all = built_simulators();
    const auto selected =
        select_simulators(all, opt.engines, "exact", "exact is the truth the sweep measures against");
    if (!selected) return kBadInput;
    const fs::path out_dir = opt.out_dir;
    if (!create_out_dir(out_dir)) return kBadInput;

    SweepRequest request;
    request.simulators = extra->for_scenario(s, *selected);
    request.dts = dts;
    request.repeat = opt.repeat;
    request.jobs = opt.jobs;
    request.budget_seconds = opt.budget;
    request.on_progress = [](const SweepRow& row, std::size_t done, std::size_t total) {
        if (row.status == RunStatus::ok)
            fmt::print(stderr, "[{}/{}] {} dt={:.6g}: error {:.4e} m, {:.1f} ns/step\n", done, total, row.engine, row.dt,
                       *row.error, row.ns_per_step.value_or(0.0));
        else
            fmt::print(stderr, "[{}/{}] {} dt={:.6g}: {}: {}\n", done, total, row.engine, row.dt,
                       to_string(row.status), row.reason);
    };
    const auto wall_start = std::chrono::steady_clock::now();
    const SweepResult result = run_sweep(s, request);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

    nlohmann::json engines = nlohmann::json::array();
    nlohmann::json origins = nlohmann::json::object();  // simulators from outside this build
    for (const Simulator* sim : request.simulators) {
        engines.push_back(std::string(sim->name()));
        if (!sim->origin().empty()) origins[std::string(sim->name())] = std::string(sim->origin());
    }
    const nlohmann::json parameters{{"scenario_file", opt.file},
                                    {"engines", engines},
                                    {"origins", origins},
                                    {"dt", dts},
                                    {"dt_source", opt.dt.empty() ? "default" : "--dt"},
                                    {"dt_argument", opt.dt},
                                    {"repeat", opt.repeat},
                                    {"jobs", opt.jobs > 0 ? opt.jobs : 0},
                                    {"budget_seconds", opt.budget},
                                    {"out", out_dir.string()}};
    fmt::print("{}", format_sweep(s, result));
    write_sweep(s, result, parameters, out_dir, to_json(this_provenance(/*with_machine=*/true)));
    fmt::print("\nwrote sweep.csv, sweep.json and sweep.html in {} ({:.2f} s)\n", out_dir.string(), wall);
    const bool any_failed = std::any_of(result.rows.begin(), result.rows.end(),
                                        [](const SweepRow& r) { return r.status == RunStatus::failed; });
    return any_failed ? kSimulatorFailed : kOk;
}

}  // namespace

Command add_sweep_command(CLI::App& app) {
    auto opt = std::make_shared<SweepOptions>();
    CLI::App* command = app.add_subcommand(
        "sweep", "Work-precision sweep: each simulator's error against exact and cost per step over a series of dt");
    command->add_option("scenario", opt->file, "Scenario file")->required();
    command->add_option("--engines", opt->engines,
                        "Comma-separated simulators (default: every one built but exact, the truth)");
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
        ->check(CLI::Range(0.001, 1e7));
    command->add_option("--out", opt->out_dir, "Output folder for sweep.csv, sweep.json and sweep.html")->capture_default_str();
    add_external_options(*command, opt->external);
    return {command, [opt] { return command_sweep(*opt); }};
}

}  // namespace bouncecheck
