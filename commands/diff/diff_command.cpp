// `bouncecheck diff OLD NEW`: what changed between two runs, each a
// report.json or the output folder holding one.
#include "commands/command.h"

#include "commands/diff/diff_pipeline.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <string>
#include <variant>
#include <vector>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

struct DiffOptions {
    std::string old_path, new_path;
    DiffJudging judging;
    std::string out_dir = "bouncecheck-out";
};

// Exit status of diff (docs/cli.md): 0 nothing changed beyond tolerance, 1
// something did, 2 bad input.
int command_diff(const DiffOptions& opt) {
    const auto tolerances = opt.judging.tolerances();
    if (!tolerances) return kBadInput;
    auto old_report = load_run_report(opt.old_path);
    auto new_report = load_run_report(opt.new_path);
    bool ok = true;
    for (const auto* loaded : {&old_report, &new_report}) {
        if (const auto* error = std::get_if<std::string>(loaded)) {
            fmt::print(stderr, "error: {}\n", *error);
            ok = false;
        }
    }
    if (!ok) return kBadInput;
    auto out = OutputFolder::open(opt.out_dir);
    if (!out) return kBadInput;
    const ReportDiff diff = diff_reports(std::get<LoadedReport>(old_report), std::get<LoadedReport>(new_report),
                                         *tolerances, opt.judging.ratio());
    fmt::print("{}", format_diff(diff, opt.judging.display));
    const WrittenFiles written = write_diff(diff, opt.out_dir, opt.judging.display);
    fmt::print("\nwrote diff.md and diff.json in {}\n", opt.out_dir);
    record_outputs(*out, "diff", written);
    return diff.changed() ? kThresholdExceeded : kOk;
}

}  // namespace

void add_diff_judging_options(CLI::App& command, DiffJudging& judging, const std::string& what) {
    add_list_option(command, "--tolerance", judging.tolerance_args,
                    what + "KEY=VALUE: the change a kind of metric may make unnoticed (height, time, trajectory, "
                           "damping, state; default 1e-9 each)");
    command.add_option("--timing-ratio", judging.timing_ratio,
                       what + "count a run time above R times the old one as a regression (default: timings are "
                              "reported, not judged)")
        ->check(finite_between(1e-6, 1e6));
    command.add_flag("--all", judging.display.all,
                     what + "list every consequence, not only each group's count and largest change");
    command.add_flag("--timings", judging.display.timings,
                     what + "show the run times compared (without it only a regression past --timing-ratio shows)");
}

Command add_diff_command(CLI::App& app) {
    auto opt = std::make_shared<DiffOptions>();
    CLI::App* command = app.add_subcommand(
        "diff", "What changed between two runs: the inputs, the settings, then the consequences per simulator");
    command->add_option("old", opt->old_path, "The baseline: a report.json, or a run's output folder")->required();
    command->add_option("new", opt->new_path, "The run to compare with it: a report.json or output folder")->required();
    add_diff_judging_options(*command, opt->judging);
    command->add_option("--out", opt->out_dir, "Output folder for diff.md and diff.json")->capture_default_str();
    set_exit_status_help(*command, {{kOk, "nothing changed beyond tolerance"},
                                   {kThresholdExceeded, "something changed beyond tolerance, or a timing regressed: named"},
                                   {kBadInput, "bad input: a file that is not a run report, with the reason"}});
    return {command, [opt] { return command_diff(*opt); }};
}

}  // namespace bouncecheck
