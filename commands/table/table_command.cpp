// `bouncecheck table REPORT`: every simulator of a run side by side, as the
// Markdown table docs/engines.md carries (scripts/engine-table.sh puts it there).
#include "commands/command.h"

#include "commands/diff/diff_pipeline.h"  // load_run_report: the one reader of report.json
#include "platform/atomic_file.h"
#include "reports/engine_table.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <string>
#include <variant>

namespace bouncecheck {

namespace {

struct TableOptions {
    std::string report;
    std::string out;  // empty: standard output
};

int command_table(const TableOptions& opt) {
    auto loaded = load_run_report(opt.report);
    if (const auto* error = std::get_if<std::string>(&loaded)) {
        fmt::print(stderr, "error: {}\n", *error);
        return kBadInput;
    }
    const std::string table = engine_table_markdown(std::get<LoadedReport>(loaded).json);
    if (opt.out.empty()) {
        fmt::print("{}", table);
        return kOk;
    }
    try {
        write_file_atomically(opt.out, table);
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: --out {}: {}\n", opt.out, e.what());
        return kBadInput;
    }
    return kOk;
}

}  // namespace

Command add_table_command(CLI::App& app) {
    auto opt = std::make_shared<TableOptions>();
    CLI::App* command = app.add_subcommand(
        "table", "Every simulator of a run side by side: engine, precision, errors against exact, measured damping, "
                 "rest and cost (Markdown)");
    command->add_option("report", opt->report, "A report.json, or a run's output folder")->required();
    command->add_option("--out", opt->out, "Write the table to this file (default: standard output)");
    set_exit_status_help(*command, {{kOk, "the table was written"},
                                   {kBadInput, "bad input: a file that is not a run report, or an --out that "
                                               "cannot be written, with the reason"}});
    return {command, [opt] { return command_table(*opt); }};
}

}  // namespace bouncecheck
