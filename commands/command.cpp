#include "commands/command.h"

#include "external/external_simulator.h"
#include "external/trajectory_reader.h"
#include "platform/did_you_mean.h"
#include "platform/printable_text.h"
#include "platform/program.h"
#include "scenarios/loader.h"

#include <CLI/CLI.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <sstream>
#include <set>

namespace fs = std::filesystem;

namespace bouncecheck {

CLI::Option* add_list_option(CLI::App& command, const std::string& name, std::vector<std::string>& items,
                             const std::string& help) {
    // One argument an occurrence, so a list never swallows the positional
    // arguments after it (`run --engines ode seed-2d.toml`); occurrences add up.
    CLI::Option* option = command.add_option(name, items, help)
                              ->delimiter(',')
                              ->type_name("LIST")
                              ->expected(1)
                              ->allow_extra_args(false)
                              ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    // CLI11 splits on the delimiter before it transforms, so each item is
    // trimmed on its own; an empty one ("a,,b", "a,") is left for the reader
    // to skip, as select_simulators does.
    option->transform(
        [](std::string item) {
            const auto first = item.find_first_not_of(" \t");
            if (first == std::string::npos) return std::string();
            return item.substr(first, item.find_last_not_of(" \t") - first + 1);
        },
        "", "trim");
    return option;
}

void add_no_timings_flag(CLI::App& command, bool& no_timings) {
    command.add_flag("--no-timings", no_timings,
                     "Leave wall-clock figures (run times, ns per step, the machine) out of every output, so that "
                     "the same input gives the same bytes");
}

std::vector<fs::path> scenario_files(const fs::path& dir) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec))
        if (entry.is_regular_file() && entry.path().extension() == ".toml") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

std::optional<std::vector<Scenario>> load_all(const std::vector<fs::path>& files,
                                              const std::vector<std::string>& external_names) {
    std::vector<Scenario> scenarios;
    bool ok = true;
    for (const auto& f : files) {
        try {
            scenarios.push_back(load_scenario(f, external_names));
        } catch (const ScenarioError& e) {
            for (const auto& d : e.diagnostics()) fmt::print(stderr, "{}\n", d.format());
            ok = false;
        }
    }
    if (!ok) return std::nullopt;
    return scenarios;
}

std::optional<std::vector<const Simulator*>> select_simulators(const std::vector<std::unique_ptr<const Simulator>>& all,
                                                               const std::vector<std::string>& engines, std::string_view excluded,
                                                               std::string_view why_excluded) {
    std::vector<std::string> wanted_names = engines;
    std::erase(wanted_names, std::string());  // "a,,b": the list's empty items
    std::vector<const Simulator*> selected;
    std::vector<std::string> known;
    for (const auto& sim : all) {
        if (sim->name() == excluded) continue;
        known.push_back(std::string(sim->name()));
        if (wanted_names.empty()) selected.push_back(sim.get());
    }
    for (const auto& wanted : wanted_names) {
        const auto it = std::find_if(all.begin(), all.end(), [&](const auto& sim) { return sim->name() == wanted; });
        if (it == all.end() || wanted == excluded) {
            const std::string why = it == all.end()
                                        ? fmt::format("unknown simulator '{}'{}", wanted, did_you_mean(wanted, known))
                                        : std::string(why_excluded);
            fmt::print(stderr, "error: --engines: {} ({}: {})\n", why, excluded.empty() ? "built" : "available",
                       fmt::join(known, ", "));
            return std::nullopt;
        }
        if (std::find(selected.begin(), selected.end(), it->get()) == selected.end()) selected.push_back(it->get());
    }
    if (selected.empty()) {
        fmt::print(stderr, "error: --engines: no simulator selected\n");
        return std::nullopt;
    }
    return selected;
}

void set_exit_status_help(CLI::App& command, const std::vector<std::pair<int, std::string>>& statuses) {
    std::string text = "Exit status:\n";
    for (const auto& [status, meaning] : statuses) text += fmt::format("  {}  {}\n", status, meaning);
    if (std::none_of(statuses.begin(), statuses.end(), [](const auto& s) { return s.first == kSimulatorFailed; }))
        text += fmt::format("  {}  an unexpected error (named on stderr)\n", int(kSimulatorFailed));
    command.footer(text);
}

void record_outputs(OutputFolder& out, std::string_view kind, const WrittenFiles& written) {
    try {
        fmt::print("{}", format_manifest_update(out.record(kind, written), out.dir()));
    } catch (const std::exception& e) {
        // The outputs are whole; only the list of them is not up to date.
        fmt::print(stderr, "warning: {}: the folder's manifest was not updated: {}\n", out.dir().string(), e.what());
    }
}

CLI::Validator finite_between(double min, double max) {
    return CLI::Validator(
        [min, max](std::string& text) -> std::string {
            const std::string shown = text.size() > 40 ? text.substr(0, 40) + "..." : text;
            double value = 0;
            if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value))
                return fmt::format("'{}' is not a finite number", shown);
            if (value < min || value > max) return fmt::format("{} is outside [{:g}, {:g}]", shown, min, max);
            return {};
        },
        fmt::format("FLOAT in [{:g}, {:g}]", min, max));
}

void add_external_options(CLI::App& command, ExternalOptions& options) {
    command.add_option("--external", options.declarations,
                       "NAME=COMMAND: run COMMAND (split on whitespace, no shell) as simulator NAME through the "
                       "external protocol, docs/external.md (repeatable)");
    command.add_option("--external-session", options.session_declarations,
                       "NAME=COMMAND: as --external, for a program that answers scenario after scenario in one "
                       "process (docs/external.md, Sessions): started once per worker, not once per run (repeatable)");
    command.add_option("--external-timeout", options.timeout_seconds,
                       "Seconds an external simulator may go without output before it is killed (it is also "
                       "killed after the command's --budget, or an hour, in all)")
        ->capture_default_str()
        ->check(finite_between(0.001, 1e6));
}

void add_scenario_programs_flag(CLI::App& command, ExternalOptions& options) {
    command.add_flag("--no-scenario-programs", options.refuse_scenario_programs,
                     "Refuse (exit 2, nothing run) a scenario file that declares a program to run ([external.NAME]): "
                     "for scenario files nobody reviewed, as a pull request's");
}

namespace {

// Why NAME cannot name a simulator bouncecheck did not build, or nothing.
std::optional<std::string> extra_name_problem(const std::string& name) {
    if (auto problem = name_problem(name)) return fmt::format("NAME {}", *problem);
    if (std::find(kBuiltInSimulators.begin(), kBuiltInSimulators.end(), name) != kBuiltInSimulators.end())
        return fmt::format("'{}' is a built-in simulator's name", name);
    return std::nullopt;
}

}  // namespace

std::optional<ExtraSimulators> ExtraSimulators::from_options(const ExternalOptions& options) {
    ExtraSimulators extra;
    extra.limits_ = options.limits();
    extra.refuse_scenario_programs_ = options.refuse_scenario_programs;
    bool ok = true;
    std::vector<std::pair<std::string, bool>> declared;  // NAME=COMMAND, and whether it is a session program
    for (const std::string& arg : options.declarations) declared.emplace_back(arg, false);
    for (const std::string& arg : options.session_declarations) declared.emplace_back(arg, true);
    for (const auto& [arg, session] : declared) {
        const auto error = [&, session = session](const std::string& why) {
            fmt::print(stderr, "error: {} {}: {}\n", session ? "--external-session" : "--external", arg, why);
            ok = false;
        };
        const auto eq = arg.find('=');
        if (eq == std::string::npos) {
            error("expected NAME=COMMAND");
            continue;
        }
        ExternalDeclaration d{arg.substr(0, eq), {}};
        d.session = session;
        std::istringstream words(arg.substr(eq + 1));
        for (std::string word; words >> word;) d.command.push_back(word);
        if (auto problem = extra_name_problem(d.name)) {
            error(*problem);
            continue;
        }
        if (std::find(extra.names_.begin(), extra.names_.end(), d.name) != extra.names_.end()) {
            error(fmt::format("'{}' is declared twice", d.name));
            continue;
        }
        if (d.command.empty()) {
            error("the command is empty");
            continue;
        }
        std::string why;
        // It runs in the scenario's folder: a relative path is taken from where it was typed.
        auto program = resolve_program(d.command[0], fs::current_path(), &why);
        if (!program) {
            error(fmt::format("cannot run the program: {}", why));
            continue;
        }
        d.command[0] = std::move(*program);
        extra.names_.push_back(d.name);
        extra.command_line_.push_back(make_external_simulator(std::move(d), options.limits()));
    }
    if (!ok) return std::nullopt;
    return extra;
}

bool ExtraSimulators::add_trajectories(const std::vector<std::string>& arguments,
                                       const std::vector<Scenario>& scenarios) {
    bool ok = true;
    for (const std::string& arg : arguments) {
        const auto error = [&](const std::string& why) {
            fmt::print(stderr, "error: --trajectory {}: {}\n", arg, why);
            ok = false;
        };
        const auto eq = arg.find('=');
        if (eq == std::string::npos || eq + 1 == arg.size()) {
            error("expected NAME=FILE.csv, or NAME@SCENARIO=FILE.csv with several scenarios");
            continue;
        }
        std::string name = arg.substr(0, eq), scenario_name;
        const std::string file = arg.substr(eq + 1);
        if (const auto at = name.find('@'); at != std::string::npos) {
            scenario_name = name.substr(at + 1);
            name.resize(at);
        }
        if (auto problem = extra_name_problem(name)) {
            error(*problem);
            continue;
        }
        const Scenario* target = nullptr;
        if (scenario_name.empty()) {
            if (scenarios.size() != 1) {
                error(fmt::format("{} scenarios are run: say which one this trajectory is of (NAME@SCENARIO=FILE)",
                                  scenarios.size()));
                continue;
            }
            target = &scenarios.front();
        } else {
            for (const Scenario& s : scenarios)
                if (s.name == scenario_name) target = &s;
            if (!target) {
                error(fmt::format("no scenario named '{}' is run", scenario_name));
                continue;
            }
        }
        const bool taken = std::find(names_.begin(), names_.end(), name) != names_.end() ||
                           target->externals.count(name) > 0 ||
                           std::any_of(imported_.begin(), imported_.end(), [&](const auto& entry) {
                               return entry.first == target->name && entry.second->name() == name;
                           });
        if (taken) {
            error(fmt::format("'{}' already names a simulator of scenario {}", name, target->name));
            continue;
        }
        if (auto problem = read_trajectory_file(file, *target, [](const State&) { return true; })) {
            error(fmt::format("not a trajectory of scenario {}: {}", target->name, *problem));
            continue;
        }
        imported_.emplace_back(target->name, make_imported_trajectory(name, file));
    }
    return ok;
}

bool ExtraSimulators::admit_scenario_programs(const std::vector<Scenario>& scenarios) const {
    if (!refuse_scenario_programs_) return true;
    bool admitted = true;
    for (const Scenario& s : scenarios) {
        for (const auto& [name, command] : s.externals) {
            fmt::print(stderr, "error: {}: [external.{}] command: would run '{}': refused (--no-scenario-programs)\n",
                       printable_text(s.source.string()), name, printable_text(fmt::format("{}", fmt::join(command, " "))));
            admitted = false;
        }
    }
    return admitted;
}

std::vector<const Simulator*> ExtraSimulators::with_command_line(const std::vector<const Simulator*>& built) const {
    std::vector<const Simulator*> out = built;
    for (const auto& sim : command_line_) out.push_back(sim.get());
    return out;
}

std::vector<const Simulator*> ExtraSimulators::for_scenario(const Scenario& s,
                                                            const std::vector<const Simulator*>& built) {
    std::vector<const Simulator*> out = with_command_line(built);
    for (const auto& [name, command] : s.externals) {
        from_files_.push_back(make_external_simulator(ExternalDeclaration{name, command}, limits_));
        out.push_back(from_files_.back().get());
    }
    for (const auto& [scenario, sim] : imported_)
        if (scenario == s.name) out.push_back(sim.get());
    return out;
}

nlohmann::json to_json(const ExternalOptions& options) {
    return {{"declarations", options.declarations},
            {"session_declarations", options.session_declarations},
            {"timeout", options.timeout_seconds},
            {"total", options.total_seconds}};
}

ExternalOptions external_options_from(const nlohmann::json& j) {
    ExternalOptions options;
    options.declarations = j.at("declarations").get<std::vector<std::string>>();
    // A shard written before sessions existed has none.
    options.session_declarations = j.value("session_declarations", std::vector<std::string>{});
    options.timeout_seconds = j.at("timeout").get<double>();
    options.total_seconds = j.at("total").get<double>();
    return options;
}

std::vector<std::string> simulator_names(const std::vector<const Simulator*>& simulators) {
    std::vector<std::string> names;
    for (const Simulator* sim : simulators) names.emplace_back(sim->name());
    return names;
}

nlohmann::json simulator_origins(const std::vector<const Simulator*>& simulators) {
    nlohmann::json origins = nlohmann::json::object();
    for (const Simulator* sim : simulators)
        if (!sim->origin().empty()) origins[std::string(sim->name())] = std::string(sim->origin());
    return origins;
}

}  // namespace bouncecheck
