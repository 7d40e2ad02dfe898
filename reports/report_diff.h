// What changed between two runs (`bouncecheck diff OLD NEW`, `run
// --baseline OLD`): the inputs first (the cause), then the settings, then
// every consequence beyond its tolerance, and the timings compared apart. The
// comparison itself is commands/diff/diff_pipeline; this is its result and
// its three renderings (terminal, diff.md, diff.json).
#pragma once

#include "platform/output_manifest.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace bouncecheck {

inline constexpr const char* kDiffSchema = "bouncecheck-diff/1";

// What a difference is: an input the scenario file gives, a setting a
// simulator reports (which an input or a build changed), or a consequence
// (a measured value that moved).
enum class DiffSection { input, setting, consequence };

// One difference beyond the tolerance of its kind.
struct DiffChange {
    DiffSection section = DiffSection::consequence;
    std::string scenario, simulator;  // simulator empty: the scenario itself
    // input: as the file writes it ("[engines.bullet] friction"); setting:
    // the key; consequence: "apex[2].height", "present", ...
    std::string metric;
    std::string kind;                  // the group: "apex heights", "contact times", ... (consequences)
    std::string old_value, new_value;  // as text; "absent" when one side lacks it
    std::string tolerance_key;         // the --tolerance key that applied; empty: any change counts
    std::optional<double> delta;       // new - old, for numbers
    std::string cause;                 // settings: the input that explains it; empty: no input changed
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

    // Each section's changes, in the order found.
    std::vector<const DiffChange*> in(DiffSection section) const;
    bool timing_regressed() const;
    // Exit 1 territory: a change beyond tolerance, or a timing regression.
    bool changed() const { return !changes.empty() || timing_regressed(); }
};

// What the renderings show besides the summary (--all, --timings).
struct DiffDisplay {
    bool all = false;      // every consequence one by one, not only each group's count and largest
    bool timings = false;  // the run times; without it only a judged regression shows
};

// The terminal's text: the inputs that changed, then the settings, then the
// consequences grouped per simulator and kind (count and largest change),
// or "no change beyond tolerance"; then the timings if shown, then both
// sides' provenance.
std::string format_diff(const ReportDiff& d, const DiffDisplay& display = {});
std::string diff_markdown(const ReportDiff& d, const DiffDisplay& display = {});  // diff.md, for a pull request
nlohmann::json diff_json(const ReportDiff& d);  // diff.json, schema bouncecheck-diff/1: every change, every timing
// diff.md and diff.json in `out_dir`, each written atomically; returns their names.
WrittenFiles write_diff(const ReportDiff& d, const std::filesystem::path& out_dir, const DiffDisplay& display = {});

}  // namespace bouncecheck
