#include "reports/report_diff.h"

#include "platform/atomic_file.h"
#include "reports/json_number.h"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>

namespace bouncecheck {

namespace {

std::string where(const DiffChange& c) {
    return c.simulator.empty() ? c.scenario : c.scenario + " / " + c.simulator;
}

std::string delta_text(const DiffChange& c) { return c.delta ? fmt::format("{:+.3e}", *c.delta) : ""; }

std::string tolerance_text(const ReportDiff& d, const DiffChange& c) {
    if (c.tolerance_key.empty()) return "any change";
    const auto it = d.tolerances.find(c.tolerance_key);
    return it == d.tolerances.end() ? c.tolerance_key : fmt::format("{} {:g}", c.tolerance_key, it->second);
}

// Markdown table cells: no pipe or newline may break the row.
std::string cell(std::string text) {
    std::string out;
    for (char ch : text) {
        if (ch == '|') out += "\\|";
        else if (ch == '\n') out += ' ';
        else out += ch;
    }
    return out;
}

}  // namespace

bool ReportDiff::timing_regressed() const {
    return std::any_of(timings.begin(), timings.end(), [](const TimingChange& t) { return t.regression; });
}

std::string format_diff(const ReportDiff& d) {
    std::string text;
    auto out = std::back_inserter(text);
    fmt::format_to(out, "\ndiff {} -> {}\n", d.old_source, d.new_source);
    if (d.changes.empty()) {
        fmt::format_to(out, "  no change beyond tolerance\n");
    } else {
        fmt::format_to(out, "  {} change{} beyond tolerance:\n", d.changes.size(), d.changes.size() == 1 ? "" : "s");
        // Grouped by scenario and simulator, the first few of each (what
        // explains the change comes first); every one is in diff.md and diff.json.
        constexpr std::size_t kShownPerGroup = 12;
        for (std::size_t i = 0; i < d.changes.size();) {
            std::size_t end = i;
            while (end < d.changes.size() && where(d.changes[end]) == where(d.changes[i])) ++end;
            fmt::format_to(out, "  {}: {} change{}\n", where(d.changes[i]), end - i, end - i == 1 ? "" : "s");
            for (std::size_t k = i; k < std::min(end, i + kShownPerGroup); ++k) {
                const DiffChange& c = d.changes[k];
                fmt::format_to(out, "    {:<30} {} -> {}{}\n", c.metric, c.old_value, c.new_value,
                               c.delta ? "  (" + delta_text(c) + ")" : "");
            }
            if (end - i > kShownPerGroup)
                fmt::format_to(out, "    ... and {} more (diff.md, diff.json)\n", end - i - kShownPerGroup);
            i = end;
        }
    }
    if (!d.timings.empty()) {
        fmt::format_to(out, "  timings (new / old{}):\n",
                       d.timing_ratio ? fmt::format(", a regression above {:g}", *d.timing_ratio)
                                      : ", reported only: --timing-ratio R makes a ratio above R a regression");
        for (const TimingChange& t : d.timings)
            fmt::format_to(out, "  {:<28} {:>10.3f} ms -> {:>10.3f} ms  x{:.2f}{}\n", t.scenario + " / " + t.simulator,
                           t.old_seconds * 1e3, t.new_seconds * 1e3, t.ratio, t.regression ? "  REGRESSION" : "");
    }
    fmt::format_to(out, "  old: {}\n  new: {}\n", d.old_provenance, d.new_provenance);
    return text;
}

std::string diff_markdown(const ReportDiff& d) {
    std::string text = "# bouncecheck diff\n\n";
    auto out = std::back_inserter(text);
    fmt::format_to(out, "- old: `{}`: {}\n- new: `{}`: {}\n\n", cell(d.old_source), cell(d.old_provenance),
                   cell(d.new_source), cell(d.new_provenance));
    if (d.changes.empty()) {
        text += "No change beyond tolerance.\n";
    } else {
        fmt::format_to(out, "**{} change{} beyond tolerance.**\n\n", d.changes.size(), d.changes.size() == 1 ? "" : "s");
        text += "| scenario | simulator | metric | old | new | delta | tolerance |\n";
        text += "| :-- | :-- | :-- | --: | --: | --: | :-- |\n";
        for (const DiffChange& c : d.changes)
            fmt::format_to(out, "| {} | {} | {} | {} | {} | {} | {} |\n", cell(c.scenario), cell(c.simulator),
                           cell(c.metric), cell(c.old_value), cell(c.new_value), delta_text(c), tolerance_text(d, c));
    }
    if (!d.timings.empty()) {
        fmt::format_to(out, "\nTimings (new / old; {}):\n\n",
                       d.timing_ratio ? fmt::format("a regression above {:g}", *d.timing_ratio)
                                      : "reported, not judged");
        text += "| scenario | simulator | old (ms) | new (ms) | ratio |\n| :-- | :-- | --: | --: | --: |\n";
        for (const TimingChange& t : d.timings)
            fmt::format_to(out, "| {} | {} | {:.3f} | {:.3f} | {}{:.2f}{} |\n", cell(t.scenario), cell(t.simulator),
                           t.old_seconds * 1e3, t.new_seconds * 1e3, t.regression ? "**" : "", t.ratio,
                           t.regression ? "**" : "");
    }
    return text;
}

nlohmann::json diff_json(const ReportDiff& d) {
    nlohmann::json changes = nlohmann::json::array(), timings = nlohmann::json::array();
    for (const DiffChange& c : d.changes)
        changes.push_back({{"scenario", c.scenario},
                           {"simulator", c.simulator},
                           {"metric", c.metric},
                           {"old", c.old_value},
                           {"new", c.new_value},
                           {"delta", json_number(c.delta)},
                           {"tolerance", c.tolerance_key.empty() ? nlohmann::json(nullptr)
                                                                 : nlohmann::json(c.tolerance_key)}});
    for (const TimingChange& t : d.timings)
        timings.push_back({{"scenario", t.scenario},
                           {"simulator", t.simulator},
                           {"old_seconds", json_number(t.old_seconds)},
                           {"new_seconds", json_number(t.new_seconds)},
                           {"ratio", json_number(t.ratio)},
                           {"regression", t.regression}});
    return {{"schema", kDiffSchema},
            {"old", {{"source", d.old_source}, {"provenance", d.old_provenance}}},
            {"new", {{"source", d.new_source}, {"provenance", d.new_provenance}}},
            {"tolerances", d.tolerances},
            {"timing_ratio", json_number(d.timing_ratio)},
            {"changed", d.changed()},
            {"changes", changes},
            {"timings", timings}};
}

void write_diff(const ReportDiff& d, const std::filesystem::path& out_dir) {
    write_file_atomically(out_dir / "diff.md", diff_markdown(d));
    write_file_atomically(out_dir / "diff.json", diff_json(d).dump(2) + "\n");
}

}  // namespace bouncecheck
