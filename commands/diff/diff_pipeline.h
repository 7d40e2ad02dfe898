// `bouncecheck diff` and `run --baseline`: two run reports (report.json)
// compared scenario by scenario and simulator by simulator, every change
// beyond its tolerance listed (reports/report_diff.h).
#pragma once

#include "reports/report_diff.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace bouncecheck {

// The tolerances, by kind of metric (--tolerance KEY=VALUE), in the metric's
// unit. The defaults let round-off through and nothing else: two runs of one
// build on one input are bit-identical, so any change a user did not make
// shows.
struct DiffTolerances {
    std::map<std::string, double> by_key{
        {"height", 1e-9},      // apex heights (m)
        {"time", 1e-9},        // apex and floor-contact times (s)
        {"trajectory", 1e-9},  // RMS and maximum distance to reference and to exact (m)
        {"damping", 1e-9},     // measured alpha and beta (mean, and per floor contact)
        {"state", 1e-9},       // the final state's position (m) and velocity (m/s)
    };
};

// KEY=VALUE into `t`; why not, if it is not one.
std::optional<std::string> parse_tolerance(const std::string& arg, DiffTolerances& t);

// --tolerance KEY=VALUE (repeatable) and --timing-ratio R: how `diff` and
// `run --baseline` judge a change; --all and --timings: what they show.
struct DiffJudging {
    std::vector<std::string> tolerance_args;
    double timing_ratio = 0;  // 0: timings reported, not judged
    DiffDisplay display;
    // The tolerances, or nothing (each bad argument printed).
    std::optional<DiffTolerances> tolerances() const;
    std::optional<double> ratio() const { return timing_ratio > 0 ? std::optional<double>(timing_ratio) : std::nullopt; }
};

// What diff reads of a report.json: at most 64 MiB (checked before reading;
// a run's report takes about 40 KB a scenario, and reading one costs about
// four times its size) and 64 levels of nesting (a report nests 8).
inline constexpr std::uintmax_t kMaxRunReportBytes = std::uintmax_t{64} << 20;
inline constexpr int kMaxRunReportDepth = 64;

// A run report read from `path`: a report.json, or an output folder holding
// one. Refused with the reason: missing, not JSON, not a run report, or a
// schema this bouncecheck does not read.
struct LoadedReport {
    nlohmann::json json;
    std::string source;  // the file read
};
std::variant<LoadedReport, std::string> load_run_report(const std::filesystem::path& path);

// Every change from `old_report` to `new_report` beyond `tolerances`;
// timings compared apart, a regression only above `timing_ratio` when given.
ReportDiff diff_reports(const LoadedReport& old_report, const LoadedReport& new_report,
                        const DiffTolerances& tolerances, std::optional<double> timing_ratio);

}  // namespace bouncecheck
