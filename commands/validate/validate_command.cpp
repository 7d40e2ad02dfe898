// `bouncecheck validate`: scenario files checked, nothing run.
#include "commands/command.h"

#include "platform/printable_text.h"
#include "scenarios/loader.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <string>
#include <vector>

namespace bouncecheck {

namespace {

struct ValidateOptions {
    std::vector<std::string> files;
    ExternalOptions external;  // the names a file's [engines.<name>] and [thresholds.<name>] may use
};

int command_validate(const ValidateOptions& opt) {
    const auto extra = ExtraSimulators::from_options(opt.external);
    if (!extra) return kBadInput;
    bool ok = true;
    for (const auto& f : opt.files) {
        try {
            const Scenario s = load_scenario(f, extra->command_line_names());
            fmt::print("{}: ok ({}, {}D)\n", f, s.name, s.dim);
            // A file that runs programs says so: the line a reviewer of a
            // pull request must see (`run --no-scenario-programs` refuses them).
            for (const auto& [name, command] : s.externals)
                fmt::print("{}: [external.{}] runs '{}' (bouncecheck run and sweep run it)\n", f, name,
                           printable_text(fmt::format("{}", fmt::join(command, " "))));
        } catch (const ScenarioError& e) {
            for (const auto& d : e.diagnostics()) fmt::print(stderr, "{}\n", d.format());
            ok = false;
        }
    }
    return ok ? kOk : kBadInput;
}

}  // namespace

Command add_validate_command(CLI::App& app) {
    auto opt = std::make_shared<ValidateOptions>();
    CLI::App* command = app.add_subcommand("validate", "Check scenario files without running them");
    command->add_option("files", opt->files, "Scenario files")->required();
    add_external_options(*command, opt->external);
    set_exit_status_help(*command, {{kOk, "every file is a valid scenario"},
                                   {kBadInput, "a file is not: each error as FILE:LINE:COLUMN: KEY: REASON"}});
    return {command, [opt] { return command_validate(*opt); }};
}

}  // namespace bouncecheck
