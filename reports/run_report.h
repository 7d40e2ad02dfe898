// Reports of a `bouncecheck run`: the terminal tables, DIR/report.json,
// DIR/report.md, DIR/junit.xml and DIR/bounces.csv. The JSON schema is
// documented in docs/report-schema.md.
#pragma once

#include "metrics/summary.h"
#include "platform/output_manifest.h"
#include "reports/plot_data.h"
#include "reports/provenance.h"
#include "reports/web_assets.h"
#include "scenarios/scenario.h"
#include "verdicts/verdicts.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

inline constexpr const char* kReportSchema = "bouncecheck-report/1";

struct ScenarioRun {
    Scenario scenario;
    std::vector<SimulatorSummary> results;  // in the order the simulators ran
    // Parallel to results: against reference and exact; empty for a skipped simulator.
    std::vector<std::optional<Comparison>> comparisons;
    // What report.html draws, when the run recorded it (RunRequest::plots).
    // Parallel to results; empty for a skipped simulator.
    struct SimulatorPlot {
        PlotTrace path;
        std::vector<double> divergence_t, divergence;  // centre distance to the reference
        std::vector<double> error_t, error;            // centre distance to exact
    };
    std::vector<std::optional<SimulatorPlot>> plots;
    PlotTrace exact_path;            // exact's path with its contacts and apexes at their instants
    std::vector<Apex> exact_apexes;  // the bars' exact values
};

struct RunReport {
    std::vector<ScenarioRun> scenarios;
    Provenance provenance;  // what was run where (the machine block left out under --no-timings)
};

nlohmann::json to_json(const RunReport& report);
// Text made safe for XML and HTML (junit.xml, the HTML pages' titles).
std::string xml_escape(std::string_view s);
// The terminal's tables: per scenario one block, its heading, then the
// summary (one row per simulator: steps, contacts, first apex heights, rest,
// run time, ns per step), then the comparison (error against exact,
// divergence from the reference, measured damping, the verdicts), then the
// engines closest to exact and to the reference (verdicts/ranking.h). A
// failed or skipped simulator's rows show only that. Fits 100 columns (names
// cut at 12 characters); ANSI colour only when `colour` (the CLI passes
// isatty(stdout)).
std::string format_run(const RunReport& report, bool colour);

// What a run's exit status is decided from, each entry "SIMULATOR on SCENARIO",
// and the status the command decided (commands/command.h has the contract).
struct RunVerdict {
    std::vector<std::string> failed;           // the run failed (exit 3)
    std::vector<std::string> exceeded;         // a threshold was exceeded (exit 1)
    std::vector<std::string> damping_differs;  // measured damping off the law (gates only through a threshold)
    bool baseline_changed = false;             // run --baseline: a change beyond tolerance (exit 1)
    int exit_status = 0;
};
RunVerdict run_verdict(const RunReport& report, bool baseline_changed = false);
// The run's last lines: its verdict and exit status in words, and a note when
// a simulator's measured damping differs from the law.
std::string format_verdict(const RunVerdict& verdict);
// report.md: the same blocks as the terminal, for a pull request, ending
// with the verdict when `verdict` is given (the file written by a run has it).
std::string to_markdown(const RunReport& report, const RunVerdict* verdict = nullptr);
std::string to_junit(const RunReport& report);      // junit.xml: a test case per scenario x simulator x threshold
std::string bounces_csv(const RunReport& report);   // bounces.csv: scenario,simulator,bounce,t,apex,measured_alpha,measured_beta
// report.html: one self-contained page (the charting library inlined) with
// the plots of every scenario that recorded them; see reports/html_report.cpp.
Page to_html(const RunReport& report);
// Writes report.json, report.md, junit.xml, bounces.csv and, when the run
// recorded plots, report.html into out_dir, each atomically. `verdict`: how
// report.md ends. Returns those names and the run's trajectory files
// (--trajectories), relative to out_dir: the run's whole output.
WrittenFiles write_reports(const RunReport& report, const std::filesystem::path& out_dir,
                           const RunVerdict* verdict = nullptr);

}  // namespace bouncecheck
