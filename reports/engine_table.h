// The table that compares every simulator of a run (`bouncecheck table`,
// docs/engines.md, "Every simulator, side by side"): one row per scenario and
// simulator of a run report (report.json), rendered as Markdown from the
// report alone, so that the docs' table is generated, never typed.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace bouncecheck {

// The Markdown table of `report` (a run report, as load_run_report gives it):
// scenario, simulator, engine and version, precision, first floor contact and
// the worst of the three apexes after the start against exact (as the law's
// check judges them, api/law_check.cpp), measured alpha and beta, rest time and
// cost per step. A field a row lacks, or holds as another type, shows as "-";
// a simulator that did not run shows its status.
std::string engine_table_markdown(const nlohmann::json& report);

}  // namespace bouncecheck
