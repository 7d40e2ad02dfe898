// `bouncecheck validate`: scenario files checked, nothing run.
#include "commands/command.h"

#include "scenarios/loader.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <string>
#include <vector>

namespace bouncecheck {

namespace {

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

}  // namespace

Command add_validate_command(CLI::App& app) {
    auto files = std::make_shared<std::vector<std::string>>();
    CLI::App* command = app.add_subcommand("validate", "Check scenario files without running them");
    command->add_option("files", *files, "Scenario files")->required();
    return {command, [files] { return command_validate(*files); }};
}

}  // namespace bouncecheck
