// Reports of a `bouncecheck run`: the terminal summary and DIR/report.json.
// The JSON schema is documented in docs/report-schema.md.
#pragma once

#include "compare/summary.h"
#include "scenarios/scenario.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace bouncecheck {

inline constexpr const char* kReportSchema = "bouncecheck-report/1";

struct ScenarioRun {
    Scenario scenario;
    std::vector<SimulatorSummary> results;  // in the order the simulators ran
};

struct RunReport {
    std::vector<ScenarioRun> scenarios;
};

nlohmann::json to_json(const RunReport& report);
void write_report_json(const RunReport& report, const std::filesystem::path& out_dir);
// Per scenario, one row per simulator: steps, contacts, first apex heights, run time.
std::string format_summary(const RunReport& report);

}  // namespace bouncecheck
