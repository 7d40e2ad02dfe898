// What every `bouncecheck` command shares: the exit status contract, how a
// command declares itself to the command line, and the steps most commands
// take before their pipeline (load the scenarios, pick the simulators, make
// the output folder). One command per folder, commands/<name>/, its
// pipeline beside it; cli/main.cpp lists them.
#pragma once

#include "platform/install_layout.h"  // bundled_scenario_dir
#include "platform/output_manifest.h"
#include "external/external_simulator.h"
#include "scenarios/scenario.h"
#include "simulators/simulator.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace CLI {
class App;
class Option;
class Validator;
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

// The end of `bouncecheck COMMAND --help`: that command's own exit statuses,
// one line each ({status, meaning}), and that an unexpected error is 3.
void set_exit_status_help(CLI::App& command, const std::vector<std::pair<int, std::string>>& statuses);

// Each declared by commands/<name>/<name>_command.cpp.
Command add_run_command(CLI::App& app);
Command add_validate_command(CLI::App& app);
Command add_list_command(CLI::App& app);
Command add_calibrate_command(CLI::App& app);
Command add_sweep_command(CLI::App& app);
Command add_stress_command(CLI::App& app);
Command add_diff_command(CLI::App& app);
Command add_merge_command(CLI::App& app);
Command add_table_command(CLI::App& app);

struct DiffJudging;
// --tolerance and --timing-ratio, for `diff` and `run --baseline` (`what` prefixes their help).
void add_diff_judging_options(CLI::App& command, DiffJudging& judging, const std::string& what = "");

// The *.toml files directly in `dir` (default: the bundled folder), by name.
std::vector<std::filesystem::path> scenario_files(const std::filesystem::path& dir = bundled_scenario_dir());
// Loads every file before anything runs; prints every diagnostic. Empty on
// failure. `external_names`: see load_scenario.
std::optional<std::vector<Scenario>> load_all(const std::vector<std::filesystem::path>& files,
                                              const std::vector<std::string>& external_names = {});
// A list option, the same in every command: items comma-separated, spaces
// around each trimmed, the flag repeatable
// (`--engines bullet,ode --engines exact`). `name` may carry aliases
// ("--engines,--engine").
CLI::Option* add_list_option(CLI::App& command, const std::string& name, std::vector<std::string>& items,
                             const std::string& help);

// --no-timings, the same in every command that writes timings.
void add_no_timings_flag(CLI::App& command, bool& no_timings);

// The check of a number option: finite and within [min, max]. CLI11's own
// Range lets NaN through (every comparison with it is false) and prints a
// refused 1e400 in 309 digits; this names the value as it was typed.
CLI::Validator finite_between(double min, double max);

// The simulators --engines names (every one in `all` if empty), in its order,
// without `excluded`. An unknown or excluded name is reported, with the
// closest known one: nothing returned.
std::optional<std::vector<const Simulator*>> select_simulators(const std::vector<std::unique_ptr<const Simulator>>& all,
                                                               const std::vector<std::string>& engines,
                                                               std::string_view excluded = {},
                                                               std::string_view why_excluded = {});
// After a command wrote `written` into its output folder as output of
// `kind`: updates the folder's manifest (removing that kind's stale files)
// and says on the terminal what it removed or left (platform/output_manifest.h).
void record_outputs(OutputFolder& out, std::string_view kind, const WrittenFiles& written);

// --external NAME=COMMAND (repeatable) and --external-timeout, shared by the
// commands that run simulators (docs/external.md).
struct ExternalOptions {
    std::vector<std::string> declarations;  // NAME=COMMAND
    // --external-session NAME=COMMAND: a program that answers scenario after
    // scenario in one process (docs/external.md, Sessions).
    std::vector<std::string> session_declarations;
    double timeout_seconds = kDefaultExternalTimeoutSeconds;
    // Not an option of its own: the command's --budget, where it has one
    // (external_simulator.h).
    double total_seconds = kDefaultExternalTotalSeconds;
    ExternalLimits limits() const { return {timeout_seconds, total_seconds}; }
    // --no-scenario-programs (run, sweep): a scenario file that declares a
    // program to run ([external.NAME]) is refused, not run.
    bool refuse_scenario_programs = false;
};
void add_external_options(CLI::App& command, ExternalOptions& options);
// --no-scenario-programs, for the commands that run a scenario file's own
// [external.NAME] programs (run, sweep): what a CI job given scenario files
// it has not reviewed (a pull request's) sets, so that they cannot run code.
void add_scenario_programs_flag(CLI::App& command, ExternalOptions& options);
// The options as a shard hands them to merge (commands/shards.h), and back.
nlohmann::json to_json(const ExternalOptions& options);
ExternalOptions external_options_from(const nlohmann::json& j);

// A report's "engines" (the simulators' names, in order) and "origins" (the
// origin of each simulator from outside this build).
std::vector<std::string> simulator_names(const std::vector<const Simulator*>& simulators);
nlohmann::json simulator_origins(const std::vector<const Simulator*>& simulators);

// The simulators bouncecheck did not build that a command runs beside the
// built ones: --external's, each scenario's own [external.<name>], and
// (`run`) --trajectory's imported files. Owns them.
class ExtraSimulators {
public:
    // Parses --external; prints every problem. Nothing on bad input.
    static std::optional<ExtraSimulators> from_options(const ExternalOptions& options);
    // Parses --trajectory NAME=FILE or NAME@SCENARIO=FILE against the loaded
    // scenarios, checking each file whole; prints every problem. False on bad input.
    bool add_trajectories(const std::vector<std::string>& arguments, const std::vector<Scenario>& scenarios);
    // The names --external declares (the loader accepts their [engines.<name>]
    // and [thresholds.<name>] tables).
    const std::vector<std::string>& command_line_names() const { return names_; }
    // The simulators `s` runs: `built`, then --external's, then its file's
    // own, then the trajectories imported for it.
    std::vector<const Simulator*> for_scenario(const Scenario& s, const std::vector<const Simulator*>& built);
    // With --no-scenario-programs: false, having named each file's
    // [external.NAME] programs on stderr, when any declares one.
    bool admit_scenario_programs(const std::vector<Scenario>& scenarios) const;
    // `built`, then --external's (the stress suite's scenarios declare none of their own).
    std::vector<const Simulator*> with_command_line(const std::vector<const Simulator*>& built) const;

private:
    ExternalLimits limits_;
    bool refuse_scenario_programs_ = false;
    std::vector<std::string> names_;
    std::vector<std::unique_ptr<const Simulator>> command_line_;
    std::vector<std::unique_ptr<const Simulator>> from_files_;
    std::vector<std::pair<std::string, std::unique_ptr<const Simulator>>> imported_;  // per scenario name
};

}  // namespace bouncecheck
