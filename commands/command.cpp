#include "commands/command.h"

#include "scenarios/loader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <sstream>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

std::vector<std::string> split_list(const std::string& list) {
    std::vector<std::string> items;
    std::stringstream ss(list);
    for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) items.push_back(item);
    return items;
}

}  // namespace

fs::path bundled_scenario_dir() {
    if (const char* dir = std::getenv("BOUNCECHECK_SCENARIOS")) return dir;
    return BOUNCECHECK_SCENARIO_DIR;
}

std::vector<fs::path> scenario_files(const fs::path& dir) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec))
        if (entry.is_regular_file() && entry.path().extension() == ".toml") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

std::optional<std::vector<Scenario>> load_all(const std::vector<fs::path>& files) {
    std::vector<Scenario> scenarios;
    bool ok = true;
    for (const auto& f : files) {
        try {
            scenarios.push_back(load_scenario(f));
        } catch (const ScenarioError& e) {
            for (const auto& d : e.diagnostics()) fmt::print(stderr, "{}\n", d.format());
            ok = false;
        }
    }
    if (!ok) return std::nullopt;
    return scenarios;
}

std::optional<std::vector<const Simulator*>> select_simulators(const std::vector<std::unique_ptr<const Simulator>>& all,
                                                               const std::string& engines, std::string_view excluded,
                                                               std::string_view why_excluded) {
    std::vector<const Simulator*> selected;
    std::string known;
    for (const auto& sim : all) {
        if (sim->name() == excluded) continue;
        known += fmt::format("{}{}", known.empty() ? "" : ", ", sim->name());
        if (engines.empty()) selected.push_back(sim.get());
    }
    for (const auto& wanted : split_list(engines)) {
        const auto it = std::find_if(all.begin(), all.end(), [&](const auto& sim) { return sim->name() == wanted; });
        if (it == all.end() || wanted == excluded) {
            const std::string why = it == all.end() ? fmt::format("unknown simulator '{}'", wanted)
                                                    : std::string(why_excluded);
            fmt::print(stderr, "error: --engines: {} ({}: {})\n", why, excluded.empty() ? "built" : "available", known);
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

bool create_out_dir(const fs::path& out_dir) {
    try {
        fs::create_directories(out_dir);
        return true;
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: --out: cannot create {}: {}\n", out_dir.string(), e.what());
        return false;
    }
}

}  // namespace bouncecheck
