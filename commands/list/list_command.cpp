// `bouncecheck list`: the bundled scenarios, the simulators this build
// contains and where each engine's module is loaded from, as aligned columns
// or (--json) as one JSON document for scripts.
#include "commands/command.h"

#include "registry/registry.h"
#include "scenarios/loader.h"
#include "reports/json_number.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <system_error>
#include <memory>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

struct ListedScenario {
    std::string name;  // the file's name when it does not load
    int dim = 0;       // 0: invalid
    std::string file;
    std::string problem;  // why it does not load
};

std::vector<ListedScenario> bundled_scenarios() {
    std::vector<ListedScenario> listed;
    for (const auto& f : scenario_files()) {
        try {
            const Scenario s = load_scenario(f);
            listed.push_back({s.name, s.dim, f.filename().string(), {}});
        } catch (const ScenarioError& e) {
            listed.push_back({f.filename().string(), 0, f.filename().string(), e.diagnostics().front().format()});
        }
    }
    return listed;
}

// "" for a file that is there, else why the engine cannot load it.
std::string module_problem(const fs::path& file) {
    std::error_code ec;
    return fs::is_regular_file(file, ec) ? std::string() : "missing";
}

int command_list(bool json) {
    const auto scenarios = bundled_scenarios();
    const auto simulators = built_simulators();
    const auto modules = engine_modules();
    if (json) {
        nlohmann::json doc = {{"scenario_dir", bundled_scenario_dir().string()},
                              {"scenarios", nlohmann::json::array()},
                              {"simulators", nlohmann::json::array()}};
        for (const ListedScenario& s : scenarios) {
            nlohmann::json entry = {{"name", s.name}, {"file", s.file}};
            if (s.problem.empty())
                entry["dim"] = s.dim;
            else
                entry["problem"] = s.problem;
            doc["scenarios"].push_back(std::move(entry));
        }
        for (const auto& sim : simulators) {
            nlohmann::json entry = {{"name", sim->name()}, {"description", sim->description()}};
            for (const EngineModule& m : modules)
                if (m.simulator == sim->name()) {
                    entry["module"] = m.file.string();
                    entry["module_found"] = module_problem(m.file).empty();
                }
            doc["simulators"].push_back(std::move(entry));
        }
        fmt::print("{}\n", json_text(doc, 2));
        return kOk;
    }
    // Columns as wide as their longest name, so that a long one never shifts the rest.
    std::size_t name_width = 0;
    for (const ListedScenario& s : scenarios) name_width = std::max(name_width, s.name.size());
    for (const auto& sim : simulators) name_width = std::max(name_width, sim->name().size());
    fmt::print("bundled scenarios ({}):\n", bundled_scenario_dir().string());
    for (const ListedScenario& s : scenarios) {
        if (s.problem.empty())
            fmt::print("  {:<{}}  {}D  {}\n", s.name, name_width, s.dim, s.file);
        else
            fmt::print("  {:<{}}  invalid: {}\n", s.name, name_width, s.problem);
    }
    fmt::print("simulators:\n");
    for (const auto& sim : simulators) fmt::print("  {:<{}}  {}\n", sim->name(), name_width, sim->description());
    if (!modules.empty()) {
        fmt::print("engine modules ({}):\n", engine_module_dir().string());
        for (const EngineModule& m : modules) {
            const std::string problem = module_problem(m.file);
            fmt::print("  {:<{}}  {}{}\n", m.simulator, name_width, m.file.filename().string(),
                       problem.empty() ? "" : "  (" + problem + ")");
        }
    }
    return kOk;
}

}  // namespace

Command add_list_command(CLI::App& app) {
    auto json = std::make_shared<bool>(false);
    CLI::App* command = app.add_subcommand("list", "Show the bundled scenarios and the simulators built");
    command->add_flag("--json", *json, "Print them as one JSON document (scenario_dir, scenarios, simulators)");
    set_exit_status_help(*command, {{kOk, "listed"}, {kBadInput, "usage error"}});
    return {command, [json] { return command_list(*json); }};
}

}  // namespace bouncecheck
