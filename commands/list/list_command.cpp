// `bouncecheck list`: the bundled scenarios and the simulators this build contains.
#include "commands/command.h"

#include "registry/registry.h"
#include "scenarios/loader.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

namespace bouncecheck {

namespace {

int command_list() {
    fmt::print("bundled scenarios ({}):\n", bundled_scenario_dir().string());
    for (const auto& f : scenario_files()) {
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

Command add_list_command(CLI::App& app) {
    CLI::App* command = app.add_subcommand("list", "Show the bundled scenarios and the simulators built");
    return {command, [] { return command_list(); }};
}

}  // namespace bouncecheck
