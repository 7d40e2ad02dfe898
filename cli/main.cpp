// The `bouncecheck` command: parses the command line and runs the one
// subcommand given. Each subcommand lives in commands/<name>/ (the exit
// status contract is in commands/command.h).
#include "commands/command.h"
#include "platform/atomic_file.h"
#include "platform/did_you_mean.h"
#include "platform/printable_text.h"
#include "reports/provenance.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <exception>
#include <string>
#include <vector>

using namespace bouncecheck;

namespace {

// The end of `bouncecheck --help`: what a newcomer types first, and what scripts rely on.
constexpr const char* kHelpFooter = R"(Examples:
  # the bundled scenarios on every simulator built
  bouncecheck run
  # my scenario on two engines, compared with reference and exact
  bouncecheck run my.toml --engines bullet,ode
  # gate CI on a limit (exit 1 when one breaks)
  bouncecheck run --threshold error_contact_time=0.01
  # gate CI on an earlier run
  bouncecheck run --baseline last/report.json
  # bring my engine (docs/external.md)
  bouncecheck run my.toml --external mine="python3 m.py"
  # error against cost over a series of dt
  bouncecheck sweep scenarios/seed-2d.toml --dt 0.01:0.001:2
  # numerical stability
  bouncecheck stress --only wall-starts,dead-ball

Exit status of run (each command's own ends its --help):
  0  ran, and every threshold (and the baseline) held
  1  a threshold or the baseline broke: the simulator and measure are named
  2  bad input or usage: nothing was run
  3  a simulator failed (the others' results are still written)

Every command's options: bouncecheck COMMAND --help
)";

// A hint for an argument the command line parser refused: the command or
// option closest to a mistyped one, from the arguments themselves (CLI11's
// message names what it refused, not what was meant).
std::string unknown_argument_hint(const CLI::App& app, int argc, char** argv) {
    std::vector<std::string> commands;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
        commands.push_back(sub->get_name());
    if (argc < 2) return {};
    const std::string first = argv[1];
    if (first.empty() || first.front() == '-') return {};
    if (std::find(commands.begin(), commands.end(), first) == commands.end()) {
        const std::string hint = did_you_mean(first, commands);
        return hint.empty() ? std::string() : fmt::format("unknown command '{}'{}", first, hint);
    }
    const CLI::App* command = app.get_subcommand(first);
    std::vector<std::string> flags = {"--help"};
    for (const CLI::Option* option : command->get_options())
        for (const std::string& name : option->get_lnames()) flags.push_back("--" + name);
    for (int i = 2; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--") break;
        if (arg.rfind("--", 0) != 0) continue;
        const std::string flag = arg.substr(0, arg.find('='));
        if (std::find(flags.begin(), flags.end(), flag) != flags.end()) continue;
        const std::string hint = did_you_mean(flag, flags);
        return fmt::format("unknown option '{}' for {}{}", flag, first,
                           hint.empty() ? fmt::format(" (see bouncecheck {} --help)", first) : hint);
    }
    return {};
}

}  // namespace

int main(int argc, char** argv) {
    remove_unfinished_files_on_interrupt();  // Ctrl-C leaves no half-written file behind
    set_command_line(argc, argv);            // for the reports' provenance
    CLI::App app{"bouncecheck: cross-checks physics engines against the seed document's bouncing-ball model"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "bouncecheck " + std::string(BOUNCECHECK_VERSION));
    app.footer(kHelpFooter);

    // In the order `bouncecheck --help` lists them.
    const std::vector<Command> commands = {add_run_command(app),       add_validate_command(app),
                                           add_list_command(app),      add_calibrate_command(app),
                                           add_sweep_command(app),     add_stress_command(app),
                                           add_diff_command(app),      add_merge_command(app),
                                           add_table_command(app)};
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
        if (const std::string hint = unknown_argument_hint(app, argc, argv); !hint.empty())
            fmt::print(stderr, "{}\n", hint);
        return kBadInput;  // usage errors share the bad-input status of the contract
    }

    try {
        for (const Command& command : commands)
            if (*command.app) return command.run();
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: {}\n", error_text(e));
        return kSimulatorFailed;
    }
    return kBadInput;
}
