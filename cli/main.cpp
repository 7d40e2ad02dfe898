// The `bouncecheck` command: parses the command line and runs the one
// subcommand given. Each subcommand lives in commands/<name>/ (the exit
// status contract is in commands/command.h).
#include "commands/command.h"
#include "platform/atomic_file.h"
#include "reports/provenance.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <exception>
#include <string>
#include <vector>

using namespace bouncecheck;

int main(int argc, char** argv) {
    remove_unfinished_files_on_interrupt();  // Ctrl-C leaves no half-written file behind
    set_command_line(argc, argv);            // for the reports' provenance
    CLI::App app{"bouncecheck: cross-checks physics engines against the seed document's bouncing-ball model"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string(BOUNCECHECK_VERSION));

    // In the order `bouncecheck --help` lists them.
    const std::vector<Command> commands = {add_run_command(app),       add_validate_command(app),
                                           add_list_command(app),      add_calibrate_command(app),
                                           add_sweep_command(app),     add_stress_command(app),
                                           add_diff_command(app),      add_merge_command(app)};
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
        for (const Command& command : commands)
            if (*command.app) return command.run();
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return kSimulatorFailed;
    }
    return kBadInput;
}
