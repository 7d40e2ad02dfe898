// `bouncecheck run`: the scenarios through every selected simulator, compared
// with the reference and exact, judged, and reported (tables, report.json,
// report.md, junit.xml, bounces.csv, report.html).
#include "commands/command.h"

#include "commands/diff/diff_pipeline.h"
#include "commands/run/run_pipeline.h"
#include "platform/did_you_mean.h"
#include "registry/registry.h"
#include "reports/run_report.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <variant>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

struct RunOptions {
    std::vector<std::string> files;
    std::vector<std::string> engines;
    std::string out_dir = "bouncecheck-out";
    bool trajectories = false;
    bool no_timings = false;
    bool in_process = false;
    double budget = 0;  // s per engine and scenario; 0: no limit
    int jobs = 0;       // 0: every core
    std::vector<std::string> threshold_args;  // KEY=VALUE
    ThresholdSet overrides;
    ExternalOptions external;
    std::vector<std::string> trajectory_args;  // NAME=FILE or NAME@SCENARIO=FILE
    std::string baseline;                      // a report.json or output folder to diff against
    DiffJudging judging;
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
        return std::nullopt;
    }
    for (const ThresholdLimit& limit : kThresholdLimits) {
        if (key != limit.key) continue;
        out.*limit.member = value;
        return std::nullopt;
    }
    std::vector<std::string> keys{"bounce_count"};
    for (const ThresholdLimit& limit : kThresholdLimits) keys.emplace_back(limit.key);
    return fmt::format("'{}': unknown key{} ({})", key, did_you_mean(key, keys), fmt::join(keys, ", "));
    return std::nullopt;
}

int command_run(RunOptions opt) {
    for (const auto& arg : opt.threshold_args) {
        if (auto error = parse_threshold(arg, opt.overrides)) {
            fmt::print(stderr, "error: --threshold {}\n", *error);
            return kBadInput;
        }
    }
    // The baseline is read before anything runs: a bad one is bad input.
    const auto tolerances = opt.judging.tolerances();
    if (!tolerances) return kBadInput;
    std::optional<LoadedReport> baseline;
    if (!opt.baseline.empty()) {
        auto loaded = load_run_report(opt.baseline);
        if (const auto* error = std::get_if<std::string>(&loaded)) {
            fmt::print(stderr, "error: --baseline {}\n", *error);
            return kBadInput;
        }
        baseline = std::move(std::get<LoadedReport>(loaded));
    }
    std::vector<fs::path> files(opt.files.begin(), opt.files.end());
    if (files.empty()) files = scenario_files();
    if (files.empty()) {
        fmt::print(stderr, "error: no scenario given and none bundled in {}\n", bundled_scenario_dir().string());
        return kBadInput;
    }
    ExternalOptions external = opt.external;
    if (opt.budget > 0) external.total_seconds = opt.budget;  // an external program's run is bounded the same
    auto extra = ExtraSimulators::from_options(external);
    if (!extra) return kBadInput;
    auto scenarios = load_all(files, extra->command_line_names());
    if (!scenarios || !extra->admit_scenario_programs(*scenarios)) return kBadInput;
    std::set<std::string> names;
    for (const auto& s : *scenarios) {
        if (!names.insert(s.name).second) {
            fmt::print(stderr, "error: two scenarios are named '{}': their outputs would collide\n", s.name);
            return kBadInput;
        }
    }

    if (!extra->add_trajectories(opt.trajectory_args, *scenarios)) return kBadInput;
    const auto all = built_simulators(external.limits());
    const auto selected = select_simulators(all, opt.engines);
    if (!selected) return kBadInput;
    const fs::path out_dir = opt.out_dir;
    auto out = OutputFolder::open(out_dir);
    if (!out) return kBadInput;
    // --trajectories writes into a folder per scenario: each checked now too,
    // not found unwritable after the run (the reference row called FAILED).
    if (opt.trajectories)
        for (const Scenario& s : *scenarios)
            if (!OutputFolder::open(out_dir / s.name)) return kBadInput;

    RunReport report;
    report.provenance = this_provenance(/*with_machine=*/!opt.no_timings);
    for (const Scenario& s : *scenarios) {
        RunRequest request{extra->for_scenario(s, *selected), out_dir, opt.trajectories, opt.overrides,
                           /*plots=*/true, /*isolate=*/!opt.in_process};
        request.budget_seconds = opt.budget;
        request.jobs = opt.jobs;
        ScenarioRun run = run_scenario(s, request);
        // Wall-clock figures are the only outputs that differ between runs of
        // the same input: without them every file is a function of the input.
        if (opt.no_timings)
            for (SimulatorSummary& r : run.results) {
                r.run_seconds = std::nan("");
                r.step_seconds.reset();
            }
        report.scenarios.push_back(std::move(run));
    }

    const bool colour = ::isatty(::fileno(stdout)) && !std::getenv("NO_COLOR");
    fmt::print("{}", format_run(report, colour));
    // The baseline is compared before the reports are written: report.md ends with the verdict.
    std::optional<ReportDiff> diff;
    if (baseline)
        diff = diff_reports(*baseline, LoadedReport{to_json(report), (out_dir / "report.json").string()}, *tolerances,
                            opt.judging.ratio());
    const bool changed = diff && diff->changed();
    RunVerdict verdict = run_verdict(report, changed);
    verdict.exit_status = run_exit_status(verdict);
    WrittenFiles written = write_reports(report, out_dir, &verdict);
    fmt::print("\nwrote report.html, report.json, report.md, junit.xml and bounces.csv in {}\n", out_dir.string());
    fmt::print("{}\n", format_provenance(report.provenance));
    if (diff) {
        fmt::print("{}", format_diff(*diff, opt.judging.display));
        for (std::string& file : write_diff(*diff, out_dir, opt.judging.display)) written.push_back(std::move(file));
        fmt::print("\nwrote diff.md and diff.json in {}\n", out_dir.string());
    }
    record_outputs(*out, "run", written);
    fmt::print("\n{}", format_verdict(verdict));
    return verdict.exit_status;
}

}  // namespace

Command add_run_command(CLI::App& app) {
    auto opt = std::make_shared<RunOptions>();
    CLI::App* command = app.add_subcommand("run", "Run scenarios on every selected simulator and write the reports");
    command->add_option("scenarios", opt->files, "Scenario files (default: the bundled ones)");
    add_list_option(*command, "--engines", opt->engines, "Simulators to run (default: every one built)");
    command->add_option("--out", opt->out_dir, "Output folder")->capture_default_str();
    command->add_flag("--trajectories", opt->trajectories,
                      "Write DIR/<scenario>/<simulator>.csv with one row per step");
    command->add_flag("--in-process", opt->in_process,
                      "Run the engines in this process, one after another, rather than in worker processes (an "
                      "engine that aborts then ends the whole run)");
    command->add_option("--jobs", opt->jobs,
                        "Engines run at once, each in a worker process (default: every core; 1 for quiet timings)")
        ->check(CLI::Range(1, 4096))
        ->excludes("--in-process");
    command->add_option("--budget", opt->budget,
                        "Wall-time limit of one engine's run of one scenario (s): past it the engine's worker process "
                        "is killed and the engine fails as hung; an external program is killed at it too (default: "
                        "no limit, and an hour for an external program; not with --in-process)")
        ->check(finite_between(0.001, 1e7))
        ->excludes("--in-process");
    add_no_timings_flag(*command, opt->no_timings);
    add_list_option(*command, "--threshold", opt->threshold_args,
                    "KEY=VALUE: a [thresholds] limit for every simulator, over the scenario's");
    add_external_options(*command, opt->external);
    add_scenario_programs_flag(*command, opt->external);
    command->add_option("--baseline", opt->baseline,
                        "Then diff against this earlier run (a report.json or output folder): exit 1 if anything "
                        "changed beyond tolerance, diff.md and diff.json beside the reports");
    add_diff_judging_options(*command, opt->judging, "With --baseline: ");
    command->add_option("--trajectory", opt->trajectory_args,
                        "NAME=FILE.csv: compare a recorded trajectory (the --trajectories CSV format) as simulator "
                        "NAME; with several scenarios NAME@SCENARIO=FILE.csv (repeatable)");
    set_exit_status_help(*command, {{kOk, "ran, and every threshold held (with --baseline: and nothing changed beyond tolerance)"},
                                   {kThresholdExceeded, "a threshold was exceeded, or with --baseline something changed: named"},
                                   {kBadInput, "bad input or usage: nothing was run"},
                                   {kSimulatorFailed, "a simulator failed: the other results and every report are still written"}});
    return {command, [opt] { return command_run(*opt); }};
}

}  // namespace bouncecheck
