#include "reports/report_diff.h"

#include "platform/atomic_file.h"
#include "reports/json_number.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>

namespace bouncecheck {

namespace {

std::string where(const DiffChange& c) {
    return c.simulator.empty() ? c.scenario : c.scenario + " / " + c.simulator;
}

std::string delta_text(const DiffChange& c) { return c.delta ? fmt::format("{:+.3e}", *c.delta) : ""; }

std::string change_text(const DiffChange& c) {
    return fmt::format("{} -> {}{}", c.old_value, c.new_value, c.delta ? " (" + delta_text(c) + ")" : "");
}

std::string cause_text(const DiffChange& c) {
    return c.cause.empty() ? "no input changed: the build or the engine did" : "follows " + c.cause;
}

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

// The consequences of one kind for one scenario's simulator: how many, and
// the largest (by |delta|; the first where none is a number).
struct ConsequenceGroup {
    std::string where, kind;
    std::size_t count = 0;
    const DiffChange* largest = nullptr;
};

std::vector<ConsequenceGroup> group_consequences(const ReportDiff& d) {
    std::vector<ConsequenceGroup> groups;
    for (const DiffChange* c : d.in(DiffSection::consequence)) {
        auto it = std::find_if(groups.begin(), groups.end(),
                               [&](const ConsequenceGroup& g) { return g.where == where(*c) && g.kind == c->kind; });
        if (it == groups.end()) it = groups.insert(groups.end(), {where(*c), c->kind, 0, c});
        ++it->count;
        const auto size = [](const DiffChange* x) { return x->delta ? std::abs(*x->delta) : -1.0; };
        if (size(c) > size(it->largest)) it->largest = c;
    }
    return groups;
}

std::string group_text(const ConsequenceGroup& g) {
    if (g.count == 1 && g.largest->metric == g.kind) return change_text(*g.largest);  // "damping verdict"
    if (g.count == 1) return fmt::format("{} {}", g.largest->metric, change_text(*g.largest));
    return fmt::format("{} changed; largest {} {}", g.count, g.largest->metric, change_text(*g.largest));
}

// The timings a rendering shows: all of them with --timings, else only the judged regressions.
std::vector<const TimingChange*> shown_timings(const ReportDiff& d, const DiffDisplay& display) {
    std::vector<const TimingChange*> shown;
    for (const TimingChange& t : d.timings)
        if (display.timings || t.regression) shown.push_back(&t);
    return shown;
}

std::string plural(std::size_t n, const char* one, const char* many) {
    return fmt::format("{} {}", n, n == 1 ? one : many);
}

}  // namespace

std::vector<const DiffChange*> ReportDiff::in(DiffSection section) const {
    std::vector<const DiffChange*> out;
    for (const DiffChange& c : changes)
        if (c.section == section) out.push_back(&c);
    return out;
}

bool ReportDiff::timing_regressed() const {
    return std::any_of(timings.begin(), timings.end(), [](const TimingChange& t) { return t.regression; });
}

std::string format_diff(const ReportDiff& d, const DiffDisplay& display) {
    std::string text;
    auto out = std::back_inserter(text);
    fmt::format_to(out, "\ndiff {} -> {}\n", d.old_source, d.new_source);
    const auto inputs = d.in(DiffSection::input), settings = d.in(DiffSection::setting);
    const auto consequences = d.in(DiffSection::consequence);
    if (d.changes.empty()) fmt::format_to(out, "  no change beyond tolerance\n");
    if (!inputs.empty()) {
        fmt::format_to(out, "  inputs changed ({}):\n", inputs.size());
        for (const DiffChange* c : inputs) fmt::format_to(out, "    {}  {}  {}\n", where(*c), c->metric, change_text(*c));
    }
    if (!settings.empty()) {
        fmt::format_to(out, "  settings changed ({}):\n", settings.size());
        for (const DiffChange* c : settings)
            fmt::format_to(out, "    {}  {}  {}  ({})\n", where(*c), c->metric, change_text(*c), cause_text(*c));
    }
    if (!consequences.empty()) {
        fmt::format_to(out, "  consequences ({} beyond tolerance):\n", consequences.size());
        if (display.all) {
            for (const DiffChange* c : consequences)
                fmt::format_to(out, "    {}  {:<24} {}\n", where(*c), c->metric, change_text(*c));
        } else {
            for (const ConsequenceGroup& g : group_consequences(d))
                fmt::format_to(out, "    {}  {}: {}\n", g.where, g.kind, group_text(g));
            fmt::format_to(out, "    (every one: --all, here and in diff.md; always in diff.json)\n");
        }
    }
    const auto timings = shown_timings(d, display);
    if (!timings.empty()) {
        fmt::format_to(out, "  timings (new / old{}):\n",
                       d.timing_ratio ? fmt::format(", a regression above {:g}", *d.timing_ratio)
                                      : ", reported only: --timing-ratio R makes a ratio above R a regression");
        for (const TimingChange* t : timings)
            fmt::format_to(out, "    {:<28} {:>10.3f} ms -> {:>10.3f} ms  x{:.2f}{}\n",
                           t->scenario + " / " + t->simulator, t->old_seconds * 1e3, t->new_seconds * 1e3, t->ratio,
                           t->regression ? "  REGRESSION" : "");
    } else if (!d.timings.empty()) {
        fmt::format_to(out, "  {} compared{} (--timings shows them)\n", plural(d.timings.size(), "timing", "timings"),
                       d.timing_ratio ? fmt::format(", none above {:g} x", *d.timing_ratio) : ", not judged");
    }
    fmt::format_to(out, "  old: {}\n  new: {}\n", d.old_provenance, d.new_provenance);
    return text;
}

std::string diff_markdown(const ReportDiff& d, const DiffDisplay& display) {
    std::string text = "# bouncecheck diff\n\n";
    auto out = std::back_inserter(text);
    fmt::format_to(out, "- old: `{}`: {}\n- new: `{}`: {}\n\n", cell(d.old_source), cell(d.old_provenance),
                   cell(d.new_source), cell(d.new_provenance));
    const auto inputs = d.in(DiffSection::input), settings = d.in(DiffSection::setting);
    const auto consequences = d.in(DiffSection::consequence);
    if (d.changes.empty()) text += "No change beyond tolerance.\n";
    if (!inputs.empty()) {
        fmt::format_to(out, "## Inputs changed ({})\n\n| scenario | input | old | new |\n| :-- | :-- | --: | --: |\n",
                       inputs.size());
        for (const DiffChange* c : inputs)
            fmt::format_to(out, "| {} | `{}` | {} | {} |\n", cell(c->scenario), cell(c->metric), cell(c->old_value),
                           cell(c->new_value));
        text += "\n";
    }
    if (!settings.empty()) {
        fmt::format_to(out, "## Settings changed ({})\n\n| scenario | simulator | setting | old | new | why |\n"
                            "| :-- | :-- | :-- | --: | --: | :-- |\n",
                       settings.size());
        for (const DiffChange* c : settings)
            fmt::format_to(out, "| {} | {} | {} | {} | {} | {} |\n", cell(c->scenario), cell(c->simulator),
                           cell(c->metric), cell(c->old_value), cell(c->new_value), cell(cause_text(*c)));
        text += "\n";
    }
    if (!consequences.empty()) {
        fmt::format_to(out, "## Consequences ({} beyond tolerance)\n\n", consequences.size());
        text += "| scenario / simulator | kind | changed | largest | old | new | delta |\n";
        text += "| :-- | :-- | --: | :-- | --: | --: | --: |\n";
        for (const ConsequenceGroup& g : group_consequences(d))
            fmt::format_to(out, "| {} | {} | {} | {} | {} | {} | {} |\n", cell(g.where), cell(g.kind), g.count,
                           cell(g.largest->metric), cell(g.largest->old_value), cell(g.largest->new_value),
                           delta_text(*g.largest));
        if (display.all) {
            text += "\nEvery one:\n\n| scenario | simulator | metric | old | new | delta | tolerance |\n";
            text += "| :-- | :-- | :-- | --: | --: | --: | :-- |\n";
            for (const DiffChange* c : consequences)
                fmt::format_to(out, "| {} | {} | {} | {} | {} | {} | {} |\n", cell(c->scenario), cell(c->simulator),
                               cell(c->metric), cell(c->old_value), cell(c->new_value), delta_text(*c),
                               tolerance_text(d, *c));
        } else {
            text += "\nEvery one is in diff.json (and here with `--all`).\n";
        }
    }
    const auto timings = shown_timings(d, display);
    if (!timings.empty()) {
        fmt::format_to(out, "\n## Timings (new / old; {})\n\n",
                       d.timing_ratio ? fmt::format("a regression above {:g}", *d.timing_ratio)
                                      : "reported, not judged");
        text += "| scenario | simulator | old (ms) | new (ms) | ratio |\n| :-- | :-- | --: | --: | --: |\n";
        for (const TimingChange* t : timings)
            fmt::format_to(out, "| {} | {} | {:.3f} | {:.3f} | {}{:.2f}{} |\n", cell(t->scenario), cell(t->simulator),
                           t->old_seconds * 1e3, t->new_seconds * 1e3, t->regression ? "**" : "", t->ratio,
                           t->regression ? "**" : "");
    }
    return text;
}

nlohmann::json diff_json(const ReportDiff& d) {
    static constexpr const char* kSectionNames[] = {"input", "setting", "consequence"};
    nlohmann::json changes = nlohmann::json::array(), timings = nlohmann::json::array();
    for (const DiffChange& c : d.changes) {
        nlohmann::json change = {{"section", kSectionNames[static_cast<int>(c.section)]},
                                 {"scenario", c.scenario},
                                 {"simulator", c.simulator},
                                 {"metric", c.metric},
                                 {"kind", c.kind},
                                 {"old", c.old_value},
                                 {"new", c.new_value},
                                 {"delta", json_number(c.delta)},
                                 {"tolerance", c.tolerance_key.empty() ? nlohmann::json(nullptr)
                                                                       : nlohmann::json(c.tolerance_key)}};
        if (c.section == DiffSection::setting)
            change["cause"] = c.cause.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.cause);
        changes.push_back(std::move(change));
    }
    nlohmann::json groups = nlohmann::json::array();
    for (const ConsequenceGroup& g : group_consequences(d))
        groups.push_back({{"where", g.where}, {"kind", g.kind}, {"count", g.count}, {"largest", g.largest->metric},
                          {"old", g.largest->old_value}, {"new", g.largest->new_value},
                          {"delta", json_number(g.largest->delta)}});
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
            {"consequence_groups", groups},
            {"timings", timings}};
}

WrittenFiles write_diff(const ReportDiff& d, const std::filesystem::path& out_dir, const DiffDisplay& display) {
    write_file_atomically(out_dir / "diff.md", diff_markdown(d, display));
    write_file_atomically(out_dir / "diff.json", json_text(diff_json(d), 2) + "\n");
    return {"diff.md", "diff.json"};
}

}  // namespace bouncecheck
