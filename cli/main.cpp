// The `bouncecheck` command: run, validate, list.
//
// Exit status (a contract, see README): 0 ran and every threshold held;
// 1 a threshold was exceeded; 2 bad input or usage, nothing run;
// 3 a simulator failed (the other results are still written).
#include "adapters/simulator.h"
#include "compare/calibrate.h"
#include "compare/report.h"
#include "compare/run.h"
#include "compare/atomic_file.h"
#include "compare/trajectory_csv.h"
#include "scenarios/loader.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
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

struct RunOptions {
    std::vector<std::string> files;
    std::string engines;
    std::string out_dir = "bouncecheck-out";
    bool trajectories = false;
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

    auto all = built_simulators();
    std::vector<const Simulator*> selected;
    if (opt.engines.empty()) {
        for (const auto& sim : all) selected.push_back(sim.get());
    } else {
        for (const auto& wanted : split_list(opt.engines)) {
            auto it = std::find_if(all.begin(), all.end(), [&](const auto& sim) { return sim->name() == wanted; });
            if (it == all.end()) {
                std::string known;
                for (const auto& sim : all) known += fmt::format("{}{}", known.empty() ? "" : ", ", sim->name());
                fmt::print(stderr, "error: --engines: unknown simulator '{}' (built: {})\n", wanted, known);
                return kBadInput;
            }
            if (std::find(selected.begin(), selected.end(), it->get()) == selected.end())
                selected.push_back(it->get());
        }
    }

    const fs::path out_dir = opt.out_dir;
    try {
        fs::create_directories(out_dir);
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: --out: cannot create {}: {}\n", out_dir.string(), e.what());
        return kBadInput;
    }

    RunReport report;
    bool any_failed = false, any_exceeded = false;
    for (const Scenario& s : *scenarios) {
        ScenarioRun run = run_scenario(s, RunRequest{selected, out_dir, opt.trajectories, opt.overrides});
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
    fmt::print("\nwrote report.json, report.md, junit.xml and bounces.csv in {}\n", out_dir.string());
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
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return kSimulatorFailed;
    }
    return kBadInput;
}
