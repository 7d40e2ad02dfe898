// What every `bouncecheck` command shares: the exit status contract, how a
// command declares itself to the command line, and the steps most commands
// take before their pipeline (load the scenarios, pick the simulators, make
// the output folder). One command per folder, commands/<name>/, its
// pipeline beside it; cli/main.cpp lists them.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/simulator.h"

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace CLI {
class App;
}

namespace bouncecheck {

// Exit status (a contract, see README): 0 ran and every threshold held;
// 1 a threshold was exceeded; 2 bad input or usage, nothing run;
// 3 a simulator failed (the other results are still written).
enum Exit { kOk = 0, kThresholdExceeded = 1, kBadInput = 2, kSimulatorFailed = 3 };

// A subcommand as declared: its options (bound to storage the command owns)
// and what runs it once the command line is parsed.
struct Command {
    CLI::App* app = nullptr;
    std::function<int()> run;
};

// Each declared by commands/<name>/<name>_command.cpp.
Command add_run_command(CLI::App& app);
Command add_validate_command(CLI::App& app);
Command add_list_command(CLI::App& app);
Command add_calibrate_command(CLI::App& app);
Command add_sweep_command(CLI::App& app);
Command add_stress_command(CLI::App& app);

// The folder of the bundled scenarios ($BOUNCECHECK_SCENARIOS, or the source tree's).
std::filesystem::path bundled_scenario_dir();
// The *.toml files directly in `dir` (default: the bundled folder), by name.
std::vector<std::filesystem::path> scenario_files(const std::filesystem::path& dir = bundled_scenario_dir());
// Loads every file before anything runs; prints every diagnostic. Empty on failure.
std::optional<std::vector<Scenario>> load_all(const std::vector<std::filesystem::path>& files);
// The simulators --engines names (every one in `all` if empty), in its order,
// without `excluded`. An unknown or excluded name is reported: nothing returned.
std::optional<std::vector<const Simulator*>> select_simulators(const std::vector<std::unique_ptr<const Simulator>>& all,
                                                               const std::string& engines,
                                                               std::string_view excluded = {},
                                                               std::string_view why_excluded = {});
// Creates --out; reports why not.
bool create_out_dir(const std::filesystem::path& out_dir);

}  // namespace bouncecheck
