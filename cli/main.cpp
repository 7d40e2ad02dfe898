// The `bouncecheck` command: run, validate, list, calibrate, sweep, stress.
//
// Exit status (a contract, see README): 0 ran and every threshold held;
// 1 a threshold was exceeded; 2 bad input or usage, nothing run;
// 3 a simulator failed (the other results are still written).
#include "commands/calibrate/calibrate_pipeline.h"
#include "commands/run/run_pipeline.h"
#include "commands/stress/stress_pipeline.h"
#include "commands/sweep/sweep_pipeline.h"
#include "platform/atomic_file.h"
#include "registry/registry.h"
#include "reports/run_report.h"
#include "reports/trajectory_csv.h"
#include "scenarios/loader.h"
#include "simulators/simulator.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace bouncecheck;

namespace {

enum Exit { kOk = 0, kThresholdExceeded = 1, kBadInput = 2, kSimulatorFailed = 3 };

fs::path bundled_scenario_dir() {
    if (const char* dir = std::getenv("BOUNCECHECK_SCENARIOS")) return dir;
    return BOUNCECHECK_SCENARIO_DIR;
}

// The bundled scenarios: *.toml directly in the scenario folder, by name.
std::vector<fs::path> bundled_scenarios() {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(bundled_scenario_dir(), ec))
        if (entry.is_regular_file() && entry.path().extension() == ".toml") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

// Loads every file before anything runs; prints every diagnostic. Empty on failure.
std::optional<std::vector<Scenario>> load_all(const std::vector<fs::path>& files) {
    std::vector<Scenario> scenarios;
    bool ok = true;
    for (const auto& f : files) {
        try {
            scenarios.push_back(load_scenario(f));
        } catch (const ScenarioError& e) {
            for (const auto& d : e.diagnostics()) fmt::print(stderr, "{}\n", d.format());
            ok = false;
        }
    }
    if (!ok) return std::nullopt;
    return scenarios;
}

std::vector<std::string> split_list(const std::string& list) {
    std::vector<std::string> items;
    std::stringstream ss(list);
    for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) items.push_back(item);
    return items;
}

// The simulators --engines names (every one in `all` if empty), in its order,
// without `excluded`. An unknown or excluded name is reported: nothing returned.
std::optional<std::vector<const Simulator*>> select_simulators(const std::vector<std::unique_ptr<const Simulator>>& all,
                                                               const std::string& engines,
                                                               std::string_view excluded = {},
                                                               std::string_view why_excluded = {}) {
    std::vector<const Simulator*> selected;
    std::string known;
    for (const auto& sim : all) {
        if (sim->name() == excluded) continue;
        known += fmt::format("{}{}", known.empty() ? "" : ", ", sim->name());
        if (engines.empty()) selected.push_back(sim.get());
    }
    for (const auto& wanted : split_list(engines)) {
        const auto it = std::find_if(all.begin(), all.end(), [&](const auto& sim) { return sim->name() == wanted; });
        if (it == all.end() || wanted == excluded) {
            const std::string why = it == all.end() ? fmt::format("unknown simulator '{}'", wanted)
                                                    : std::string(why_excluded);
            fmt::print(stderr, "error: --engines: {} ({}: {})\n", why, excluded.empty() ? "built" : "available", known);
            return std::nullopt;
        }
        if (std::find(selected.begin(), selected.end(), it->get()) == selected.end()) selected.push_back(it->get());
    }
    if (selected.empty()) {
        fmt::print(stderr, "error: --engines: no simulator selected\n");
        return std::nullopt;
    }
    return selected;
}

bool create_out_dir(const fs::path& out_dir) {
    try {
        fs::create_directories(out_dir);
        return true;
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: --out: cannot create {}: {}\n", out_dir.string(), e.what());
        return false;
    }
}

struct RunOptions {
    std::vector<std::string> files;
    std::string engines;
    std::string out_dir = "bouncecheck-out";
    bool trajectories = false;
    bool no_timings = false;
    bool in_process = false;
    std::vector<std::string> threshold_args;  // KEY=VALUE
    ThresholdSet overrides;
};

// --threshold KEY=VALUE: a [thresholds] key and its limit, over every simulator's.
std::optional<std::string> parse_threshold(const std::string& arg, ThresholdSet& out) {
    const auto eq = arg.find('=');
    if (eq == std::string::npos) return fmt::format("'{}' is not KEY=VALUE", arg);
    const std::string key = arg.substr(0, eq), text = arg.substr(eq + 1);
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(value) || value < 0)
        return fmt::format("'{}': the limit must be a finite number >= 0", arg);
    if (key == "bounce_count") {
        if (value < 1 || value > 10000 || value != std::floor(value))
            return fmt::format("'{}': bounce_count must be an integer within [1, 10000]", arg);
        out.bounce_count = static_cast<int>(value);
    } else if (key == "bounce_height_rel") out.bounce_height_rel = value;
    else if (key == "trajectory_rms") out.trajectory_rms = value;
    else if (key == "trajectory_max") out.trajectory_max = value;
    else if (key == "restitution_abs") out.restitution_abs = value;
    else if (key == "tangential_abs") out.tangential_abs = value;
    else
        return fmt::format("'{}': unknown key (bounce_count, bounce_height_rel, trajectory_rms, trajectory_max, "
                           "restitution_abs, tangential_abs)", key);
    return std::nullopt;
}

int command_run(RunOptions opt) {
    for (const auto& arg : opt.threshold_args) {
        if (auto error = parse_threshold(arg, opt.overrides)) {
            fmt::print(stderr, "error: --threshold {}\n", *error);
            return kBadInput;
        }
    }
    std::vector<fs::path> files(opt.files.begin(), opt.files.end());
    if (files.empty()) files = bundled_scenarios();
    if (files.empty()) {
        fmt::print(stderr, "error: no scenario given and none bundled in {}\n", bundled_scenario_dir().string());
        return kBadInput;
    }
    auto scenarios = load_all(files);
    if (!scenarios) return kBadInput;
    std::set<std::string> names;
    for (const auto& s : *scenarios) {
        if (!names.insert(s.name).second) {
            fmt::print(stderr, "error: two scenarios are named '{}': their outputs would collide\n", s.name);
            return kBadInput;
        }
    }

    const auto all = built_simulators();
    const auto selected = select_simulators(all, opt.engines);
    if (!selected) return kBadInput;
    const fs::path out_dir = opt.out_dir;
    if (!create_out_dir(out_dir)) return kBadInput;

    RunReport report;
    bool any_failed = false, any_exceeded = false;
    for (const Scenario& s : *scenarios) {
        ScenarioRun run = run_scenario(s, RunRequest{*selected, out_dir, opt.trajectories, opt.overrides, /*plots=*/true,
                                                      /*isolate=*/!opt.in_process});
        // Wall-clock figures are the only outputs that differ between runs of
        // the same input: without them every file is a function of the input.
        if (opt.no_timings)
            for (SimulatorSummary& r : run.results) r.run_seconds = std::nan("");
        for (std::size_t i = 0; i < run.results.size(); ++i) {
            any_failed = any_failed || run.results[i].status == RunStatus::failed;
            any_exceeded = any_exceeded || (run.comparisons[i] && !run.comparisons[i]->passed());
        }
        report.scenarios.push_back(std::move(run));
    }

    fmt::print("{}", format_summary(report));
    const bool colour = ::isatty(::fileno(stdout)) && !std::getenv("NO_COLOR");
    fmt::print("{}", format_comparison(report, colour));
    write_reports(report, out_dir);
    fmt::print("\nwrote report.html, report.json, report.md, junit.xml and bounces.csv in {}\n", out_dir.string());
    if (any_failed) return kSimulatorFailed;
    return any_exceeded ? kThresholdExceeded : kOk;
}

int command_validate(const std::vector<std::string>& files) {
    bool ok = true;
    for (const auto& f : files) {
        try {
            const Scenario s = load_scenario(f);
            fmt::print("{}: ok ({}, {}D)\n", f, s.name, s.dim);
        } catch (const ScenarioError& e) {
            for (const auto& d : e.diagnostics()) fmt::print(stderr, "{}\n", d.format());
            ok = false;
        }
    }
    return ok ? kOk : kBadInput;
}

struct CalibrateOptions {
    std::string file;
    std::string engine;
    double max_mu = 1.0;
    bool write = false;
};

int command_calibrate(const CalibrateOptions& opt) {
    auto scenarios = load_all({opt.file});
    if (!scenarios) return kBadInput;
    const Scenario& s = scenarios->front();
    auto all = built_simulators();
    const auto it = std::find_if(all.begin(), all.end(), [&](const auto& sim) { return sim->name() == opt.engine; });
    if (it == all.end() || opt.engine == "reference" || opt.engine == "exact") {
        fmt::print(stderr, "error: --engine: '{}' is not a built engine\n", opt.engine);
        return kBadInput;
    }
    if (s.engine_options(opt.engine).tangential_model != TangentialModel::friction) {
        fmt::print(stderr, "error: {}: [engines.{}] uses tangential_model = \"per-contact\"; calibration tunes friction\n",
                   opt.file, opt.engine);
        return kBadInput;
    }
    if (auto why = (*it)->cannot_run(s)) {
        fmt::print(stderr, "error: {}: {}\n", opt.file, *why);
        return kBadInput;
    }
    const CalibrationResult r = calibrate_friction(s, **it, opt.max_mu);
    fmt::print("{} on {}: objective = RMS distance of the ball centre from reference over the run\n", opt.engine,
               s.name);
    fmt::print("  mu = {:.6g}: divergence {:.4g} m (mu = 0: {:.4g} m; {} runs)\n", r.mu, r.divergence,
               r.divergence_at_zero, r.evaluated.size());
    if (opt.write) {
        std::ifstream in(opt.file, std::ios::binary);
        std::stringstream text;
        text << in.rdbuf();
        write_file_atomically(opt.file, with_calibrated_friction(text.str(), opt.file, opt.engine, r.mu, r.divergence));
        fmt::print("  wrote friction = {:.6g} into [engines.{}] of {}\n", r.mu, opt.engine, opt.file);
    }
    return kOk;
}

struct SweepOptions {
    std::string file;
    std::string engines;
    std::string dt;
    int repeat = 3;
    int jobs = 0;  // 0: every core
    std::string out_dir = "bouncecheck-out";
};

int command_sweep(const SweepOptions& opt) {
    auto scenarios = load_all({opt.file});
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
    request.simulators = *selected;
    request.dts = dts;
    request.repeat = opt.repeat;
    request.jobs = opt.jobs;
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
    for (const Simulator* sim : *selected) engines.push_back(std::string(sim->name()));
    const nlohmann::json parameters{{"scenario_file", opt.file},
                                    {"engines", engines},
                                    {"dt", dts},
                                    {"dt_source", opt.dt.empty() ? "default" : "--dt"},
                                    {"dt_argument", opt.dt},
                                    {"repeat", opt.repeat},
                                    {"jobs", opt.jobs > 0 ? opt.jobs : 0},
                                    {"out", out_dir.string()}};
    fmt::print("{}", format_sweep(s, result));
    write_sweep(s, result, parameters, out_dir);
    fmt::print("\nwrote sweep.csv, sweep.json and sweep.html in {} ({:.2f} s)\n", out_dir.string(), wall);
    const bool any_failed = std::any_of(result.rows.begin(), result.rows.end(),
                                        [](const SweepRow& r) { return r.status == RunStatus::failed; });
    return any_failed ? kSimulatorFailed : kOk;
}

struct StressOptions {
    std::string engines;
    int jobs = 0;  // 0: every core
    std::string out_dir = "bouncecheck-out";
    std::vector<std::string> only;  // rows or scenario names
    double budget = kDefaultBudgetSeconds;
};

// Exit status of stress (README): 0 every invariant held; 1 an invariant
// broke, a finding about a simulator; 3 a simulator threw or gave up, so the
// matrix has a hole (over 1: the run is incomplete); 2 bad input.
int command_stress(const StressOptions& opt) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(bundled_scenario_dir() / "stress", ec))
        if (entry.is_regular_file() && entry.path().extension() == ".toml") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    auto scenarios = load_all(files);
    if (!scenarios) return kBadInput;
    std::vector<StressCase> cases = stress_suite(*scenarios);
    if (!opt.only.empty()) {
        std::vector<StressCase> chosen;
        for (const auto& name : opt.only) {
            const auto matches = [&](const StressCase& c) { return c.row == name || c.scenario.name == name; };
            if (std::none_of(cases.begin(), cases.end(), matches)) {
                std::set<std::string> rows;
                for (const auto& c : cases) rows.insert(c.row);
                fmt::print(stderr, "error: --only: no stress scenario or row '{}' (rows: {})\n", name,
                           fmt::join(rows, ", "));
                return kBadInput;
            }
        }
        std::copy_if(cases.begin(), cases.end(), std::back_inserter(chosen), [&](const StressCase& c) {
            return std::any_of(opt.only.begin(), opt.only.end(),
                               [&](const std::string& n) { return c.row == n || c.scenario.name == n; });
        });
        cases = std::move(chosen);
    }
    const auto all = built_simulators();
    const auto selected = select_simulators(all, opt.engines);
    if (!selected) return kBadInput;
    const fs::path out_dir = opt.out_dir;
    if (!create_out_dir(out_dir)) return kBadInput;

    StressRequest request;
    request.simulators = *selected;
    request.jobs = opt.jobs;
    request.budget_seconds = opt.budget;
    request.on_progress = [](const StressResult& r, std::size_t done, std::size_t total) {
        if (r.row == r.scenario || r.outcome == StressOutcome::crashed)
            fmt::print(stderr, "[{}/{}] {} {}: {}{}{}\n", done, total, r.scenario, r.simulator, to_string(r.outcome),
                       r.reason.empty() ? "" : ": ", r.reason);
    };
    const StressReport report = run_stress(cases, request);
    nlohmann::json engines = nlohmann::json::array();
    for (const Simulator* sim : *selected) engines.push_back(std::string(sim->name()));
    const nlohmann::json parameters{{"engines", engines},
                                    {"jobs", opt.jobs > 0 ? opt.jobs : 0},
                                    {"only", opt.only},
                                    {"budget_seconds", opt.budget},
                                    {"out", out_dir.string()}};
    fmt::print("{}{}", format_stress_matrix(report), format_stress_failures(report));
    write_stress(report, cases, parameters, out_dir);
    fmt::print("\nwrote stress.json and stress.csv in {}\n", out_dir.string());
    const auto any = [&](StressOutcome o) {
        return std::any_of(report.results.begin(), report.results.end(),
                           [&](const StressResult& r) { return r.outcome == o; });
    };
    if (any(StressOutcome::crashed)) return kSimulatorFailed;
    return any(StressOutcome::fail) ? kThresholdExceeded : kOk;
}

int command_list() {
    fmt::print("bundled scenarios ({}):\n", bundled_scenario_dir().string());
    for (const auto& f : bundled_scenarios()) {
        try {
            const Scenario s = load_scenario(f);
            fmt::print("  {:<12} {}D  {}\n", s.name, s.dim, f.filename().string());
        } catch (const ScenarioError& e) {
            fmt::print("  {:<12} invalid: {}\n", f.filename().string(), e.diagnostics().front().format());
        }
    }
    fmt::print("simulators:\n");
    for (const auto& sim : built_simulators()) fmt::print("  {:<12} {}\n", sim->name(), sim->description());
    return kOk;
}

}  // namespace

int main(int argc, char** argv) {
    remove_unfinished_files_on_interrupt();  // Ctrl-C leaves no half-written file behind
    CLI::App app{"bouncecheck: cross-checks physics engines against the seed document's bouncing-ball model"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string(BOUNCECHECK_VERSION));

    RunOptions run_opt;
    auto* run = app.add_subcommand("run", "Run scenarios on every selected simulator and write the reports");
    run->add_option("scenarios", run_opt.files, "Scenario files (default: the bundled ones)");
    run->add_option("--engines", run_opt.engines, "Comma-separated simulators to run (default: every one built)");
    run->add_option("--out", run_opt.out_dir, "Output folder")->capture_default_str();
    run->add_flag("--trajectories", run_opt.trajectories,
                  "Write DIR/<scenario>/<simulator>.csv with one row per step");
    run->add_flag("--in-process", run_opt.in_process,
                  "Run the engines in this process rather than each in a child process (an engine that "
                  "aborts then ends the whole run)");
    run->add_flag("--no-timings", run_opt.no_timings,
                  "Leave run times out of every output, so that the same input gives the same bytes");
    run->add_option("--threshold", run_opt.threshold_args,
                    "KEY=VALUE: a [thresholds] limit for every simulator, over the scenario's (repeatable)");

    std::vector<std::string> validate_files;
    auto* validate = app.add_subcommand("validate", "Check scenario files without running them");
    validate->add_option("files", validate_files, "Scenario files")->required();

    auto* list = app.add_subcommand("list", "Show the bundled scenarios and the simulators built");

    CalibrateOptions calibrate_opt;
    auto* calibrate = app.add_subcommand(
        "calibrate", "Find the friction coefficient mu that brings an engine closest to the reference");
    calibrate->add_option("scenario", calibrate_opt.file, "Scenario file")->required();
    calibrate->add_option("--engine", calibrate_opt.engine, "Engine to calibrate")->required();
    calibrate->add_option("--max-mu", calibrate_opt.max_mu, "Upper end of the search")
        ->capture_default_str()
        ->check(CLI::Range(1e-3, 10.0));
    calibrate->add_flag("--write", calibrate_opt.write, "Write the value into the file's [engines.<engine>] table");

    SweepOptions sweep_opt;
    auto* sweep = app.add_subcommand(
        "sweep", "Work-precision sweep: each simulator's error against exact and cost per step over a series of dt");
    sweep->add_option("scenario", sweep_opt.file, "Scenario file")->required();
    sweep->add_option("--engines", sweep_opt.engines,
                      "Comma-separated simulators (default: every one built but exact, the truth)");
    sweep->add_option("--dt", sweep_opt.dt,
                      "Time steps: a list 0.03,0.015,... or FROM:TO:FACTOR (FROM, FROM/FACTOR, ... while >= TO). "
                      "Default: the scenario's dt halved down to max(1e-5, dt/2^7), capped to keep a run quick");
    sweep->add_option("--repeat", sweep_opt.repeat, "Timed runs per (simulator, dt); the fastest is kept")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000));
    sweep->add_option("--jobs", sweep_opt.jobs, "(simulator, dt) pairs run at once (default: every core)")
        ->check(CLI::Range(1, 4096));
    sweep->add_option("--out", sweep_opt.out_dir, "Output folder for sweep.csv, sweep.json and sweep.html")->capture_default_str();

    StressOptions stress_opt;
    auto* stress = app.add_subcommand(
        "stress", "Run the stress suite (scenarios/stress/*.toml, wall starts, a Monte-Carlo set) on every selected "
                  "simulator and check its invariants");
    stress->add_option("--engines", stress_opt.engines, "Comma-separated simulators (default: every one built)");
    stress->add_option("--jobs", stress_opt.jobs, "Runs at once (default: every core)")->check(CLI::Range(1, 4096));
    stress->add_option("--out", stress_opt.out_dir, "Output folder for stress.json and stress.csv")
        ->capture_default_str();
    stress->add_option("--only", stress_opt.only,
                       "Only these rows (a scenario's name, monte-carlo, wall-starts) or generated scenarios")
        ->expected(1, -1);
    stress->add_option("--budget", stress_opt.budget, "Wall-time budget of one run (s)")
        ->capture_default_str()
        ->check(CLI::Range(0.001, 86400.0));

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return kBadInput;  // usage errors share the bad-input status of the contract
    }

    try {
        if (*run) return command_run(run_opt);
        if (*validate) return command_validate(validate_files);
        if (*list) return command_list();
        if (*calibrate) return command_calibrate(calibrate_opt);
        if (*sweep) return command_sweep(sweep_opt);
        if (*stress) return command_stress(stress_opt);
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return kSimulatorFailed;
    }
    return kBadInput;
}
