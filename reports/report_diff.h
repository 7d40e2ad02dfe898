// What changed between two runs (`bouncecheck diff OLD NEW`, `run
// --baseline OLD`): every difference beyond its tolerance, scenario by
// scenario and simulator by simulator, and the timings compared apart. The
// comparison itself is commands/diff/diff_pipeline; this is its result and
// its three renderings (terminal, diff.md, diff.json).
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace bouncecheck {

inline constexpr const char* kDiffSchema = "bouncecheck-diff/1";

// One difference: a metric of a scenario's simulator (or the scenario or
// simulator itself appearing or disappearing) whose values differ by more
// than the tolerance of its kind.
struct DiffChange {
    std::string scenario, simulator;  // simulator empty: the scenario itself
    std::string metric;               // "apex[2].height", "setting friction", "present", ...
    std::string old_value, new_value;  // as text; "absent" when one side lacks it
    std::string tolerance_key;         // the --tolerance key that applied; empty: any change counts
    std::optional<double> delta;       // new - old, for numbers
};

struct TimingChange {
    std::string scenario, simulator;
    double old_seconds = 0, new_seconds = 0;
    double ratio = 0;  // new / old
    bool regression = false;  // ratio > --timing-ratio, when given
};

struct ReportDiff {
    std::string old_source, new_source;          // the files compared
    std::string old_provenance, new_provenance;  // one line each (format_provenance)
    std::map<std::string, double> tolerances;    // as applied
    std::optional<double> timing_ratio;
    std::vector<DiffChange> changes;
    std::vector<TimingChange> timings;

    bool timing_regressed() const;
    // Exit 1 territory: a change beyond tolerance, or a timing regression.
    bool changed() const { return !changes.empty() || timing_regressed(); }
};

// The terminal's table: what changed (or "no change beyond tolerance"),
// then the timings, then both sides' provenance.
std::string format_diff(const ReportDiff& d);
std::string diff_markdown(const ReportDiff& d);  // diff.md, ready for a pull request
nlohmann::json diff_json(const ReportDiff& d);   // diff.json, schema bouncecheck-diff/1
// diff.md and diff.json in `out_dir`, each written atomically.
void write_diff(const ReportDiff& d, const std::filesystem::path& out_dir);

}  // namespace bouncecheck
