#include "reports/run_report.h"

#include "platform/atomic_file.h"
#include "reports/json_number.h"
#include "verdicts/ranking.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string_view>

namespace bouncecheck {

namespace {

// ---------------------------------------------------------------- JSON

// JSON has no NaN or infinity: they are written as null.


nlohmann::json vec_json(const Vec3& v, int dim) {
    nlohmann::json a = nlohmann::json::array();
    for (int i = 0; i < dim; ++i) a.push_back(json_number(v[i]));
    return a;
}

// A ThresholdSet with its unset limits omitted.
nlohmann::json threshold_set_json(const ThresholdSet& t) {
    nlohmann::json j = nlohmann::json::object();
    if (t.bounce_count) j["bounce_count"] = *t.bounce_count;
    for (const ThresholdLimit& limit : kThresholdLimits)
        if (t.*limit.member) j[limit.key] = json_number(*(t.*limit.member));
    return j;
}

// Each [engines.<name>] table as the file gives it (every key, a default
// where the file leaves one out; an external's table as written), so that
// `diff` names a changed setting as the file writes it.
nlohmann::json engines_json(const Scenario& s) {
    nlohmann::json engines = nlohmann::json::object();
    for (const auto& [name, o] : s.engines) {
        nlohmann::json table = {
            {"tangential_model", o.tangential_model == TangentialModel::per_contact ? "per-contact" : "friction"},
            {"rotation", o.free_rotation ? "free" : "locked"},
            {"substeps", o.substeps}};
        if (o.tangential_model == TangentialModel::friction) table["friction"] = json_number(o.friction);
        if (o.ccd) table["ccd"] = *o.ccd;
        engines[name] = std::move(table);
    }
    for (const auto& [name, text] : s.passthrough_tables) {
        nlohmann::json table = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
        engines[name] = table.is_discarded() ? nlohmann::json(nullptr) : std::move(table);  // the loader checked it
    }
    return engines;
}

nlohmann::json scenario_json(const Scenario& s) {
    nlohmann::json overrides = nlohmann::json::object();
    for (const auto& [name, set] : s.thresholds.simulator) overrides[name] = threshold_set_json(set);
    return {
        {"name", s.name},
        {"file", s.source.string()},
        {"dim", s.dim},
        {"room", vec_json(s.room, s.dim)},
        {"radius", json_number(s.radius)},
        {"position", vec_json(s.position, s.dim)},
        {"velocity", vec_json(s.velocity, s.dim)},
        {"gravity", vec_json(s.gravity, s.dim)},
        {"alpha", json_number(s.alpha)},
        {"beta", json_number(s.beta)},
        {"dt", json_number(s.dt)},
        {"duration", json_number(s.duration)},
        {"engines", engines_json(s)},
        {"thresholds", {{"all", threshold_set_json(s.thresholds.all)}, {"simulators", overrides}}},
    };
}

nlohmann::json trajectory_json(const TrajectoryDivergence& t) {
    return {
        {"samples", t.samples},
        {"rms", json_number(t.rms)},
        {"max", json_number(t.max)},
        {"rest_cut", json_number(t.rest_cut)},
        {"rms_before_rest", json_number(t.rms_before_rest)},
        {"max_before_rest", json_number(t.max_before_rest)},
        {"tolerance", json_number(t.tolerance)},
        {"first_exceeds", json_number(t.first_exceeds)},
    };
}

nlohmann::json divergence_json(const Divergence& d) {
    nlohmann::json bounces = nlohmann::json::array();
    for (const BounceDiff& b : d.bounces) {
        bounces.push_back({
            {"index", b.index},
            {"height", json_number(b.height)},
            {"baseline_height", json_number(b.baseline_height)},
            {"abs_diff", json_number(b.abs_diff)},
            {"rel_diff", json_number(b.rel_diff)},
            {"contact_t", json_number(b.contact_t)},
            {"baseline_contact_t", json_number(b.baseline_contact_t)},
        });
    }
    return {
        {"baseline", d.baseline},
        {"bounces", bounces},
        {"bounce_height_rel_max", json_number(d.bounce_height_rel_max)},
        {"contact_time_max", json_number(d.contact_time_max)},
        {"apexes_self", d.apexes_self},
        {"apexes_baseline", d.apexes_baseline},
        {"note", d.note},
        {"trajectory", trajectory_json(d.trajectory)},
    };
}

nlohmann::json damping_json(const DampingCheck& d) {
    return {
        {"contacts", d.contacts},
        {"tangential_contacts", d.tangential_contacts},
        {"normal_mean", json_number(d.normal_mean)},
        {"normal_worst", json_number(d.normal_worst)},
        {"tangential_mean", json_number(d.tangential_mean)},
        {"tangential_worst", json_number(d.tangential_worst)},
        {"normal_tolerance", json_number(d.normal_tolerance)},
        {"tangential_tolerance", json_number(d.tangential_tolerance)},
        {"tangential_loss_mean", json_number(d.tangential_loss_mean)},
        {"tangential_loss_rel", json_number(d.tangential_loss_rel)},
        {"tangential_loss_tolerance", json_number(d.tangential_loss_tolerance)},
        {"reproduces", d.reproduces},
        {"verdict", d.verdict},
    };
}

nlohmann::json comparison_json(const Comparison& c) {
    nlohmann::json thresholds = nlohmann::json::array();
    for (const ThresholdCheck& t : c.thresholds) {
        thresholds.push_back(
            {{"metric", t.metric}, {"measured", json_number(t.measured)}, {"limit", json_number(t.limit)}, {"passed", t.passed}});
    }
    return {
        {"vs_reference", divergence_json(c.vs_reference)},
        {"vs_exact", divergence_json(c.vs_exact)},
        {"damping", damping_json(c.damping)},
        {"thresholds", thresholds},
        {"passed", c.passed()},
    };
}

constexpr std::size_t kJsonContacts = 200;

nlohmann::json result_json(const SimulatorSummary& r, const Comparison* c, int dim) {
    nlohmann::json j = {{"simulator", r.simulator}, {"status", to_string(r.status)}};
    if (!r.origin.empty()) j["origin"] = r.origin;
    if (!r.reason.empty()) j["reason"] = r.reason;
    if (r.status == RunStatus::skipped) return j;
    j["steps"] = r.steps;
    j["contacts"] = r.contacts;
    j["floor_contacts"] = r.floor_contacts;
    j["contacts_unbounded"] = r.contacts_unbounded;
    j["apex_count"] = r.apex_count;
    nlohmann::json apexes = nlohmann::json::array();
    for (const Apex& a : r.apexes) apexes.push_back({{"t", json_number(a.t)}, {"height", json_number(a.height)}});
    j["apexes"] = apexes;
    nlohmann::json floor = nlohmann::json::array();
    for (const ContactEvent& e : r.contact_events) {
        if (e.axis != dim - 1 || e.side > 0) continue;
        if (floor.size() == kReportedApexes) break;
        floor.push_back({{"t", json_number(e.t)}, {"restitution", json_number(e.normal_coefficient)}});
    }
    j["first_floor_contacts"] = floor;
    nlohmann::json measured = nlohmann::json::array();
    for (std::size_t i = 0; i < r.contact_events.size() && i < kJsonContacts; ++i) {
        const ContactEvent& e = r.contact_events[i];
        measured.push_back({{"t", json_number(e.t)},
                            {"axis", e.axis},
                            {"side", e.side},
                            {"normal_coefficient", json_number(e.normal_coefficient)},
                            {"tangential_retention", json_number(e.tangential_retention)}});
    }
    j["contacts_measured"] = measured;
    j["max_penetration"] = json_number(r.max_penetration);
    j["energy_max_rise"] = json_number(r.energy_max_rise);
    j["rest_time"] = json_number(r.rest_time);
    j["filled_from"] = json_number(r.filled_from);
    j["fill_period_steps"] = r.fill_period;
    j["fill_steps"] = r.fill_steps;
    j["final_state"] = {{"t", json_number(r.final_state.t)},
                        {"position", vec_json(r.final_state.p, dim)},
                        {"velocity", vec_json(r.final_state.v, dim)}};
    j["run_seconds"] = json_number(r.run_seconds);
    j["ns_per_step"] = json_number(r.ns_per_step());
    if (r.step_seconds) {  // the engine timed its own steps: what the run spent outside them, apart
        j["step_seconds"] = json_number(*r.step_seconds);
        j["outside_step_seconds"] = json_number(r.run_seconds - *r.step_seconds);
    }
    if (!r.trajectory_file.empty()) j["trajectory"] = r.trajectory_file;
    if (!r.settings.empty()) {
        nlohmann::json settings = nlohmann::json::array();
        for (const auto& st : r.settings) settings.push_back({{"key", st.key}, {"value", st.value}, {"why", st.why}});
        j["settings"] = settings;
    }
    if (c) j["comparison"] = comparison_json(*c);
    return j;
}

// The comparison of run.results[i], if there is one.
const Comparison* comparison_of(const ScenarioRun& run, std::size_t i) {
    if (i >= run.comparisons.size() || !run.comparisons[i]) return nullptr;
    return &*run.comparisons[i];
}

// ---------------------------------------------------------------- comparison table

// One row of the comparison table, as text cells (shared by terminal and Markdown).
struct Row {
    std::string simulator;
    RunStatus status = RunStatus::ok;
    std::string reason;
    // Against exact first: the figures that rank engines (bounce heights,
    // contact times, how long the path stays within the tracking tolerance),
    // where a whole-run RMS is dominated by one shifted event or by sliding
    // after rest. Then the divergence from the reference.
    std::string apex_exact = "-", contact_exact = "-", rms_before_rest = "-", tracks_exact = "-", apex_ref = "-";
    std::string alpha = "-", beta = "-", damping = "-", thresholds = "-";
    // The summary's cells: what the simulator did, and what it cost.
    std::string steps, contacts, apexes, rest = "-", run_time = "-", ns_per_step = "-";
    bool damping_ok = true, thresholds_ok = true;
    std::vector<const ThresholdCheck*> failed;
    const Comparison* comparison = nullptr;
};

std::string percent(double ratio) {
    const double p = ratio * 100.0;
    if (std::isfinite(p) && std::abs(p) >= 1000.0) return fmt::format("{:.3g}%", p);
    return fmt::format("{:.2f}%", p);
}

std::string seconds(double s) { return fmt::format("{:.3g} s", s); }

// A distance in 9 characters at most: 3 significant digits, 2 when its exponent needs the room.
std::string metres(double m) {
    std::string text = fmt::format("{:.3g} m", m);
    return text.size() <= 9 ? text : fmt::format("{:.2g} m", m);
}

// Measured and limit of a threshold: 6 significant digits, or all of them
// when 6 would print a failed measurement equal to its limit.
std::pair<std::string, std::string> threshold_numbers(const ThresholdCheck& t) {
    std::string measured = fmt::format("{:.6g}", t.measured), limit = fmt::format("{:.6g}", t.limit);
    if (measured == limit) {
        measured = fmt::format("{}", t.measured);
        limit = fmt::format("{}", t.limit);
    }
    return {measured, limit};
}

Row make_row(const ScenarioRun& run, std::size_t i) {
    const SimulatorSummary& r = run.results[i];
    Row row;
    row.simulator = r.simulator;
    row.status = r.status;
    row.reason = r.reason;
    if (r.status == RunStatus::skipped) return row;
    row.steps = fmt::format("{}", r.steps);
    row.contacts = fmt::format("{}{}", r.contacts, r.contacts_unbounded ? "+inf" : "");
    for (std::size_t k = 0; k < r.apexes.size() && k < 4; ++k)
        row.apexes += fmt::format("{}{:.4f}", k ? " " : "", r.apexes[k].height);
    if (r.rest_time) row.rest = fmt::format("{:.2f}", *r.rest_time);
    if (std::isfinite(r.run_seconds)) row.run_time = fmt::format("{:.3f}ms", r.run_seconds * 1e3);
    if (r.steps > 0 && std::isfinite(r.ns_per_step())) {
        const double ns = r.ns_per_step();
        row.ns_per_step = std::abs(ns) < 1e6 ? fmt::format("{:.1f}", ns) : fmt::format("{:.3g}", ns);
    }
    const Comparison* c = comparison_of(run, i);
    row.comparison = c;
    if (!c || r.status == RunStatus::failed) return row;  // a failed run's figures rank nothing
    const bool is_exact = r.simulator == c->vs_exact.baseline;  // exact against itself ranks nothing
    if (!is_exact && !c->vs_exact.bounces.empty()) row.apex_exact = percent(c->vs_exact.bounce_height_rel_max);
    if (!is_exact && c->vs_exact.contact_time_max) row.contact_exact = seconds(*c->vs_exact.contact_time_max);
    if (!is_exact && c->vs_exact.trajectory.samples > 0) {
        row.rms_before_rest = metres(c->vs_exact.trajectory.rms_before_rest);
        row.tracks_exact = c->vs_exact.trajectory.first_exceeds ? seconds(*c->vs_exact.trajectory.first_exceeds)
                                                                 : std::string("whole run");
    }
    if (!c->vs_reference.bounces.empty()) row.apex_ref = percent(c->vs_reference.bounce_height_rel_max);
    if (c->damping.contacts > 0) row.alpha = fmt::format("{:.4f}", c->damping.normal_mean);
    if (c->damping.tangential_contacts > 0) row.beta = fmt::format("{:.4f}", c->damping.tangential_mean);
    row.damping_ok = c->damping.reproduces;
    row.damping = c->damping.reproduces ? "ok" : "DIFFERS";
    for (const ThresholdCheck& t : c->thresholds)
        if (!t.passed) row.failed.push_back(&t);
    if (!c->thresholds.empty()) {
        row.thresholds_ok = row.failed.empty();
        row.thresholds = row.failed.empty() ? std::string("pass") : fmt::format("FAIL {}", row.failed.size());
    }
    return row;
}

constexpr std::size_t kWidth = 100;

// Visible width: UTF-8 code points, ANSI escape sequences excluded.
std::size_t visible_width(std::string_view s) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const auto ch = static_cast<unsigned char>(s[i]);
        if (ch == 0x1b && i + 1 < s.size() && s[i + 1] == '[') {
            i += 2;
            while (i < s.size() && !(s[i] >= 0x40 && s[i] <= 0x7e)) ++i;
            continue;
        }
        if ((ch & 0xc0) != 0x80) ++n;
    }
    return n;
}

std::string pad(std::string_view s, std::size_t width, bool right) {
    const std::size_t w = visible_width(s);
    const std::string fill(w < width ? width - w : 0, ' ');
    return right ? fill + std::string(s) : std::string(s) + fill;
}

// Cuts s to `width` code points, ending with "…" when cut.
std::string truncate(std::string_view s, std::size_t width) {
    if (visible_width(s) <= width) return std::string(s);
    std::string out;
    std::size_t n = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const auto ch = static_cast<unsigned char>(s[i]);
        if ((ch & 0xc0) != 0x80 && ++n > width - 1) break;
        out += s[i];
    }
    return out + "…";
}

// `first` followed by `text`, wrapped at kWidth; continuation lines start with
// `indent` spaces. A short parenthesis is one word, so a value never parts
// from its unit ("(9.51 s)").
constexpr std::size_t kShortParenthesis = 24;
std::vector<std::string> wrap(const std::string& first, std::string_view text, std::size_t indent) {
    std::vector<std::string> lines;
    std::string line = first;
    bool line_has_word = false;
    std::size_t pos = 0;
    while (pos < text.size()) {
        while (pos < text.size() && (text[pos] == ' ' || text[pos] == '\n' || text[pos] == '\t')) ++pos;
        if (pos >= text.size()) break;
        std::size_t end = pos;
        while (end < text.size() && text[end] != ' ' && text[end] != '\n' && text[end] != '\t') ++end;
        // A short parenthesis left open by the word ("(9.51") runs on to its close.
        const std::string_view so_far = text.substr(pos, end - pos);
        if (const auto open = so_far.rfind('('); open != std::string_view::npos && so_far.find(')', open) == so_far.npos)
            if (const auto close = text.find(')', end); close != text.npos && close - (pos + open) <= kShortParenthesis)
                for (end = close + 1; end < text.size() && text[end] != ' ' && text[end] != '\n' && text[end] != '\t';)
                    ++end;
        std::string word(text.substr(pos, end - pos));
        pos = end;
        for (;;) {
            const std::size_t used = visible_width(line) + (line_has_word ? 1 : 0);
            const std::size_t room = used < kWidth ? kWidth - used : 0;
            const std::size_t w = visible_width(word);
            if (w <= room) {
                if (line_has_word) line += ' ';
                line += word;
                line_has_word = true;
                break;
            }
            const bool fits_a_line = indent + w <= kWidth;
            if (line_has_word && (fits_a_line || room < 2)) {  // start a new line, then retry
                lines.push_back(line);
                line = std::string(indent, ' ');
                line_has_word = false;
                continue;
            }
            // A word longer than a whole line: fill this line with its start (on code point boundaries).
            if (line_has_word) line += ' ';
            std::size_t cut = 0, n = 0;
            while (cut < word.size() && n < room) {
                ++cut;
                while (cut < word.size() && (static_cast<unsigned char>(word[cut]) & 0xc0) == 0x80) ++cut;
                ++n;
            }
            line += word.substr(0, cut);
            lines.push_back(line);
            line = std::string(indent, ' ');
            line_has_word = false;
            word = word.substr(cut);
        }
    }
    lines.push_back(line);
    return lines;
}

constexpr const char* kGreen = "\x1b[32m";
constexpr const char* kRed = "\x1b[31m";
constexpr const char* kYellow = "\x1b[33m";
constexpr const char* kReset = "\x1b[0m";

std::string paint(const std::string& s, const char* colour, bool on) {
    return on ? std::string(colour) + s + kReset : s;
}

std::string heading(const Scenario& s) {
    return fmt::format("{} ({}D, dt = {:g} s, duration = {:g} s)", s.name, s.dim, s.dt, s.duration);
}

// The summary table: what each simulator did and what it cost.
const char* const kSummaryColumns[] = {"simulator", "steps",    "contacts", "first apex heights (m)",
                                       "rest (s)",  "run time", "ns/step"};
// The comparison table: how far each is from exact and the reference, and the verdicts.
const char* const kColumns[] = {"simulator", "apex err", "contact err", "rms<rest", "tracks exact", "apex div",
                                "alpha",     "beta",     "damping",     "thresholds"};

// "NAME (value)", ties joined: the leader of one ranked figure.
std::string leader_text(const Leader& l, const std::string& value) {
    return fmt::format("{} ({})", fmt::join(l.simulators, ", "), value);
}

// Which engine is closest to exact and which to the reference (verdicts/ranking.h); empty with no engine.
std::string ranking_text(const ScenarioRanking& ranking) {
    std::vector<std::string> exact;
    if (ranking.apex_error) exact.push_back("apex heights " + leader_text(*ranking.apex_error, percent(ranking.apex_error->value)));
    if (ranking.contact_error)
        exact.push_back("contact times " + leader_text(*ranking.contact_error, seconds(ranking.contact_error->value)));
    if (ranking.tracks_exact)
        exact.push_back("tracks longest " + leader_text(*ranking.tracks_exact, ranking.tracks_exact->whole_run
                                                                                  ? std::string("whole run")
                                                                                  : seconds(ranking.tracks_exact->value)));
    std::string text;
    if (!exact.empty()) text = fmt::format("closest to exact: {}", fmt::join(exact, ", "));
    if (ranking.apex_divergence)
        text += fmt::format("{}closest to the reference: {}", text.empty() ? "" : "; ",
                            leader_text(*ranking.apex_divergence, percent(ranking.apex_divergence->value)));
    return text;
}

// ---------------------------------------------------------------- Markdown, XML, CSV text

std::string md_cell(std::string_view s) {
    std::string out;
    for (char ch : s) {
        if (ch == '|') out += "\\|";
        else if (ch == '\n' || ch == '\r') out += ' ';
        else out += ch;
    }
    return out;
}


std::string csv_field(std::string_view s) {
    if (s.find_first_of(",\"\n\r") == std::string_view::npos) return std::string(s);
    std::string out = "\"";
    for (char ch : s) {
        if (ch == '"') out += '"';
        out += ch;
    }
    return out + "\"";
}

std::string csv_number(double v) { return std::isfinite(v) ? fmt::format("{:.17g}", v) : std::string(); }

}  // namespace

std::string xml_escape(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (char ch : s) {
        switch (ch) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&apos;"; break;
            default:
                // XML 1.0 forbids most control characters, even escaped.
                if (static_cast<unsigned char>(ch) < 0x20 && ch != '\t' && ch != '\n' && ch != '\r') out += '?';
                else out += ch;
        }
    }
    return out;
}

namespace {

// One ranked figure's leader, or null where no engine has the figure.
nlohmann::json leader_json(const std::optional<Leader>& l) {
    if (!l) return nullptr;
    nlohmann::json j = {{"simulators", l->simulators}, {"value", json_number(l->value)}};
    if (l->whole_run) j["value"] = nullptr;  // tracked exact over the whole run
    return j;
}

nlohmann::json ranking_json(const ScenarioRanking& r) {
    return {{"apex_error", leader_json(r.apex_error)},
            {"contact_error", leader_json(r.contact_error)},
            {"tracks_exact", leader_json(r.tracks_exact)},
            {"apex_divergence", leader_json(r.apex_divergence)}};
}

}  // namespace

nlohmann::json to_json(const RunReport& report) {
    nlohmann::json scenarios = nlohmann::json::array();
    for (const ScenarioRun& run : report.scenarios) {
        nlohmann::json results = nlohmann::json::array();
        for (std::size_t i = 0; i < run.results.size(); ++i)
            results.push_back(result_json(run.results[i], comparison_of(run, i), run.scenario.dim));
        scenarios.push_back({{"scenario", scenario_json(run.scenario)},
                             {"simulators", results},
                             {"ranking", ranking_json(rank_simulators(run.results, run.comparisons))}});
    }
    return {{"schema", kReportSchema},
            {"bouncecheck_version", BOUNCECHECK_VERSION},
            {"provenance", to_json(report.provenance)},
            {"scenarios", scenarios}};
}

namespace {

// Width of the name column: the longest name, within [9, 12].
std::size_t name_width_of(const ScenarioRun& run) {
    std::size_t width = 9;
    for (const SimulatorSummary& r : run.results) width = std::max(width, visible_width(r.simulator));
    return std::min<std::size_t>(width, 12);
}

// A table's header: the name column left-aligned, the others right-aligned at `widths`.
template <std::size_t N>
std::string header_line(const char* const (&columns)[N], const std::size_t (&widths)[N], std::size_t name_width) {
    std::string header = "  " + pad(columns[0], name_width, false);
    for (std::size_t c = 1; c < N; ++c) header += " " + pad(columns[c], widths[c], true);
    return header + '\n';
}

// One scenario's block: its heading, the summary, the comparison, and the ranking line.
std::string format_scenario(const ScenarioRun& run, bool colour) {
    // Summary: steps, contacts, first apex heights (left-aligned, 31), rest, run time, ns/step.
    static constexpr std::size_t kSummaryWidths[] = {0, 9, 9, 31, 8, 10, 9};
    // Comparison: at most 100 columns (names cut at 12 characters).
    static constexpr std::size_t kWidths[] = {0, 8, 11, 9, 12, 8, 6, 6, 7, 10};
    const std::size_t name_width = name_width_of(run);
    const std::size_t indent = name_width + 3;  // where a row's first cell starts
    std::string text = "\n";
    for (const std::string& line : wrap("", heading(run.scenario), 2)) text += line + '\n';

    // `what` after the row's name, wrapped at kWidth and painted.
    auto message = [&](std::string& out, const std::string& name, const std::string& what, const char* paint_colour) {
        const std::vector<std::string> lines = wrap(name, what, indent);
        for (std::size_t l = 0; l < lines.size(); ++l) {
            const std::size_t prefix = l == 0 ? name.size() : indent;
            out += lines[l].substr(0, prefix) + paint(lines[l].substr(prefix), paint_colour, colour) + '\n';
        }
    };
    std::vector<Row> rows;
    for (std::size_t i = 0; i < run.results.size(); ++i) rows.push_back(make_row(run, i));
    auto name_cell = [&](const Row& row) { return "  " + pad(truncate(row.simulator, name_width), name_width, false) + ' '; };

    std::string header = "  " + pad(kSummaryColumns[0], name_width, false);
    for (std::size_t c = 1; c < std::size(kSummaryColumns); ++c)
        header += c == 3 ? "  " + pad(kSummaryColumns[c], kSummaryWidths[c], false)
                         : " " + pad(kSummaryColumns[c], kSummaryWidths[c], true);
    text += header + '\n';
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const Row& row = rows[i];
        const SimulatorSummary& r = run.results[i];
        if (!r.origin.empty()) message(text, "  ", fmt::format("{} ({})", row.simulator, r.origin), nullptr);
        if (row.status == RunStatus::skipped) {
            message(text, name_cell(row), "skipped: " + row.reason, kYellow);
            continue;
        }
        if (row.status == RunStatus::failed) {  // its partial figures are in report.json
            message(text, name_cell(row), "FAILED: " + row.reason, kRed);
            continue;
        }
        text += name_cell(row) + pad(row.steps, kSummaryWidths[1], true) + ' ' +
                pad(row.contacts, kSummaryWidths[2], true) + "  " + pad(row.apexes, kSummaryWidths[3], false) + ' ' +
                pad(row.rest, kSummaryWidths[4], true) + ' ' + pad(row.run_time, kSummaryWidths[5], true) + ' ' +
                pad(row.ns_per_step, kSummaryWidths[6], true);
        while (!text.empty() && text.back() == ' ') text.pop_back();
        text += '\n';
        if (r.filled_from)
            message(text, std::string(indent, ' '),
                    fmt::format("states repeat from t = {:.6g} s (every {} step{}): the last {} filled, not computed",
                                *r.filled_from, r.fill_period, r.fill_period == 1 ? "" : "s", r.fill_steps),
                    nullptr);
    }

    text += '\n';
    text += header_line(kColumns, kWidths, name_width);
    for (const Row& row : rows) {
        if (row.status == RunStatus::skipped) {
            message(text, name_cell(row), "skipped", kYellow);
            continue;
        }
        if (row.status == RunStatus::failed) {
            message(text, name_cell(row), "FAILED", kRed);
            continue;
        }
        std::string line = name_cell(row);
        const std::string cells[] = {row.apex_exact, row.contact_exact, row.rms_before_rest, row.tracks_exact,
                                     row.apex_ref,   row.alpha,         row.beta};
        for (std::size_t c = 0; c < std::size(cells); ++c) {
            if (c) line += ' ';
            line += pad(truncate(cells[c], kWidths[c + 1]), kWidths[c + 1], true);
        }
        line += ' ';
        line += paint(pad(row.damping, kWidths[8], true), row.damping_ok ? kGreen : kRed, colour && row.comparison);
        line += ' ';
        line += paint(pad(row.thresholds, kWidths[9], true), row.thresholds_ok ? kGreen : kRed,
                      colour && row.comparison && !row.comparison->thresholds.empty());
        text += line + '\n';
        for (const ThresholdCheck* t : row.failed) {
            const auto [measured, limit] = threshold_numbers(*t);
            for (const std::string& l : wrap("      ", fmt::format("{} = {} > {}", t->metric, measured, limit), 8))
                text += l + '\n';
        }
    }
    const std::string ranking = ranking_text(rank_simulators(run.results, run.comparisons));
    if (!ranking.empty())
        for (const std::string& line : wrap("  ", ranking, 4)) text += line + '\n';
    return text;
}

}  // namespace

std::string format_run(const RunReport& report, bool colour) {
    std::string text;
    for (const ScenarioRun& run : report.scenarios) text += format_scenario(run, colour);
    return text;
}

RunVerdict run_verdict(const RunReport& report, bool baseline_changed) {
    RunVerdict verdict;
    verdict.baseline_changed = baseline_changed;
    for (const ScenarioRun& run : report.scenarios) {
        for (std::size_t i = 0; i < run.results.size(); ++i) {
            const SimulatorSummary& r = run.results[i];
            const std::string who = fmt::format("{} on {}", r.simulator, run.scenario.name);
            if (r.status == RunStatus::failed) {
                verdict.failed.push_back(who);
                continue;
            }
            const Comparison* c = comparison_of(run, i);
            if (!c || r.status != RunStatus::ok) continue;
            if (!c->passed()) verdict.exceeded.push_back(who);
            if (!c->damping.reproduces) verdict.damping_differs.push_back(who);
        }
    }
    return verdict;
}

namespace {

// "a, b and 3 more": the first few of a list, for one line.
std::string first_few(const std::vector<std::string>& items) {
    constexpr std::size_t kShown = 3;
    if (items.size() <= kShown) return fmt::format("{}", fmt::join(items, ", "));
    return fmt::format("{} and {} more", fmt::join(items.begin(), items.begin() + kShown, ", "), items.size() - kShown);
}

}  // namespace

namespace {

// The verdict, then the note on damping if any: each one unwrapped line.
std::vector<std::string> verdict_sentences(const RunVerdict& verdict) {
    std::vector<std::string> parts;
    if (!verdict.failed.empty())
        parts.push_back(fmt::format("{} simulator run{} failed ({}); the other results are written",
                                    verdict.failed.size(), verdict.failed.size() == 1 ? "" : "s",
                                    first_few(verdict.failed)));
    if (!verdict.exceeded.empty())
        parts.push_back(fmt::format("{} exceeded a threshold ({})",
                                    verdict.exceeded.size() == 1 ? std::string("one run")
                                                                 : fmt::format("{} runs", verdict.exceeded.size()),
                                    first_few(verdict.exceeded)));
    if (verdict.baseline_changed) parts.push_back("the results changed from the baseline beyond tolerance");
    if (parts.empty()) parts.push_back("every simulator ran and every threshold held");
    std::vector<std::string> sentences{
        fmt::format("verdict: {} (exit {})", fmt::join(parts, "; "), verdict.exit_status)};
    // Not an exit status of its own (a threshold gates it), but worth saying.
    if (!verdict.damping_differs.empty())
        sentences.push_back(fmt::format("note: the measured damping differs from the law for {} (a [thresholds] "
                                        "restitution_abs, tangential_abs or tangential_loss_rel gates it)",
                                        first_few(verdict.damping_differs)));
    return sentences;
}

}  // namespace

std::string format_verdict(const RunVerdict& verdict) {
    std::string text;
    for (const std::string& sentence : verdict_sentences(verdict)) {
        const std::size_t label = sentence.find(' ') + 1;  // continuation lines line up after "verdict: "
        for (const std::string& line : wrap(sentence.substr(0, label), sentence.substr(label), label))
            text += line + '\n';
    }
    return text;
}

std::string to_markdown(const RunReport& report, const RunVerdict* verdict) {
    std::string text = "# bouncecheck report\n";
    auto out = std::back_inserter(text);
    if (!report.provenance.build.version.empty())  // a report built in code (tests) has none
        fmt::format_to(out, "\n{}\n", md_cell(format_provenance(report.provenance)));
    for (const ScenarioRun& run : report.scenarios) {
        const Scenario& s = run.scenario;
        fmt::format_to(out, "\n## {}\n\n", md_cell(heading(s)));
        std::vector<Row> rows;
        for (std::size_t i = 0; i < run.results.size(); ++i) rows.push_back(make_row(run, i));

        text += "|";
        for (const char* column : kSummaryColumns) fmt::format_to(out, " {} |", column);
        text += "\n| :-- | --: | --: | :-- | --: | --: | --: |\n";
        for (const Row& row : rows) {
            const std::string name = md_cell(row.simulator);
            if (row.status == RunStatus::skipped)
                fmt::format_to(out, "| {} | skipped: {} |  |  |  |  |  |\n", name, md_cell(row.reason));
            else if (row.status == RunStatus::failed)
                fmt::format_to(out, "| {} | **FAILED**: {} |  |  |  |  |  |\n", name, md_cell(row.reason));
            else
                fmt::format_to(out, "| {} | {} | {} | {} | {} | {} | {} |\n", name, row.steps, row.contacts,
                               row.apexes, row.rest, row.run_time, row.ns_per_step);
        }

        text += "\n|";
        for (const char* column : kColumns) fmt::format_to(out, " {} |", column);
        text += "\n| :-- | --: | --: | --: | --: | --: | --: | --: | :-- | :-- |\n";
        std::vector<std::string> failures, verdicts, origins;
        for (std::size_t i = 0; i < rows.size(); ++i) {
            const Row& row = rows[i];
            const std::string name = md_cell(row.simulator);
            if (!run.results[i].origin.empty())
                origins.push_back(fmt::format("- {}: {}", name, md_cell(run.results[i].origin)));
            if (row.status == RunStatus::skipped) {
                fmt::format_to(out, "| {} | skipped |  |  |  |  |  |  |  |  |\n", name);
                continue;
            }
            if (row.status == RunStatus::failed) {
                fmt::format_to(out, "| {} | **FAILED** |  |  |  |  |  |  |  |  |\n", name);
                failures.push_back(fmt::format("- {}: **FAILED**: {}", name, md_cell(row.reason)));
                continue;
            }
            const std::string thresholds = row.thresholds_ok ? row.thresholds : "**" + row.thresholds + "**";
            const std::string damping = row.damping_ok ? row.damping : "**" + row.damping + "**";
            fmt::format_to(out, "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", name, row.apex_exact,
                           row.contact_exact, row.rms_before_rest, row.tracks_exact, row.apex_ref, row.alpha, row.beta,
                           damping, thresholds);
            for (const ThresholdCheck* t : row.failed) {
                const auto [measured, limit] = threshold_numbers(*t);
                failures.push_back(fmt::format("- {}: `{}` = {} > {}", name, t->metric, measured, limit));
            }
            if (row.comparison && !row.comparison->damping.verdict.empty())
                verdicts.push_back(fmt::format("- {}: {}", name, md_cell(row.comparison->damping.verdict)));
        }
        const std::string ranking = ranking_text(rank_simulators(run.results, run.comparisons));
        if (!ranking.empty()) fmt::format_to(out, "\n{}\n", md_cell(ranking));
        if (!failures.empty()) {
            text += "\nFailures:\n\n";
            for (const std::string& f : failures) text += f + '\n';
        }
        if (!verdicts.empty()) {
            text += "\nDamping:\n\n";
            for (const std::string& v : verdicts) text += v + '\n';
        }
        if (!origins.empty()) {
            text += "\nSimulators from outside this build:\n\n";
            for (const std::string& o : origins) text += o + '\n';
        }
    }
    if (verdict) {
        const std::vector<std::string> sentences = verdict_sentences(*verdict);
        for (std::size_t i = 0; i < sentences.size(); ++i)
            text += i == 0 ? fmt::format("\n**{}**\n", md_cell(sentences[i])) : fmt::format("\n{}\n", md_cell(sentences[i]));
    }
    return text;
}

std::string to_junit(const RunReport& report) {
    struct Case {
        std::string name;
        std::string failure;  // message; empty if none
        std::string failure_text;
        std::string skipped;  // message; empty if not skipped
        bool is_skipped = false;
    };
    std::string suites;
    int total = 0, total_failures = 0, total_skipped = 0;
    auto out = std::back_inserter(suites);
    for (const ScenarioRun& run : report.scenarios) {
        const std::string scenario = run.scenario.name;
        std::string cases;
        int tests = 0, failures = 0, skipped = 0;
        for (std::size_t i = 0; i < run.results.size(); ++i) {
            const SimulatorSummary& r = run.results[i];
            const Comparison* c = comparison_of(run, i);
            const std::string classname = xml_escape(scenario + "." + r.simulator);
            std::vector<Case> list;
            if (c && r.status != RunStatus::skipped) {
                for (const ThresholdCheck& t : c->thresholds) {
                    Case k{t.metric, "", "", "", false};
                    if (!t.passed) {
                        const auto [measured, limit] = threshold_numbers(t);
                        k.failure = fmt::format("{}: {} = {} exceeds limit {}", r.simulator, t.metric, measured, limit);
                        k.failure_text = fmt::format("scenario {}, simulator {}: {} = {} exceeds limit {}", scenario,
                                                     r.simulator, t.metric, t.measured, t.limit);
                    }
                    list.push_back(std::move(k));
                }
            }
            // One "run" case when no threshold was checked, and always for a failed run
            // (so a failure is never hidden behind passing thresholds).
            if (list.empty() || r.status == RunStatus::failed) {
                Case k{"run", "", "", "", false};
                if (r.status == RunStatus::failed) {
                    k.failure = fmt::format("{}: FAILED: {}", r.simulator, r.reason);
                    k.failure_text = k.failure;
                } else if (r.status == RunStatus::skipped) {
                    k.is_skipped = true;
                    k.skipped = r.reason;
                }
                list.push_back(std::move(k));
            }
            for (const Case& k : list) {
                ++tests;
                fmt::format_to(std::back_inserter(cases), "    <testcase classname=\"{}\" name=\"{}\"", classname,
                               xml_escape(k.name));
                if (!k.failure.empty()) {
                    ++failures;
                    fmt::format_to(std::back_inserter(cases),
                                   ">\n      <failure message=\"{}\">{}</failure>\n    </testcase>\n",
                                   xml_escape(k.failure), xml_escape(k.failure_text));
                } else if (k.is_skipped) {
                    ++skipped;
                    fmt::format_to(std::back_inserter(cases), ">\n      <skipped message=\"{}\"/>\n    </testcase>\n",
                                   xml_escape(k.skipped));
                } else {
                    cases += "/>\n";
                }
            }
        }
        fmt::format_to(out, "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"{}\">\n",
                       xml_escape(scenario), tests, failures, skipped);
        suites += cases;
        suites += "  </testsuite>\n";
        total += tests;
        total_failures += failures;
        total_skipped += skipped;
    }
    return fmt::format(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        "<testsuites name=\"bouncecheck\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"{}\">\n{}"
        "</testsuites>\n",
        total, total_failures, total_skipped, suites);
}

std::string bounces_csv(const RunReport& report) {
    std::string text = "scenario,simulator,bounce,t,apex,measured_alpha,measured_beta\n";
    auto out = std::back_inserter(text);
    for (const ScenarioRun& run : report.scenarios) {
        const int floor_axis = run.scenario.dim - 1;
        for (const SimulatorSummary& r : run.results) {
            // Floor contacts in time order; the one ending bounce k is the first after its apex.
            std::vector<const ContactEvent*> floor;
            for (const ContactEvent& e : r.contact_events)
                if (e.axis == floor_axis && e.side == -1) floor.push_back(&e);
            std::size_t next = 0;
            for (std::size_t k = 0; k < r.apexes.size(); ++k) {
                const Apex& a = r.apexes[k];
                while (next < floor.size() && !(floor[next]->t > a.t)) ++next;
                std::string alpha, beta;
                if (next < floor.size()) {
                    alpha = csv_number(floor[next]->normal_coefficient);
                    beta = csv_number(floor[next]->tangential_retention);
                }
                fmt::format_to(out, "{},{},{},{},{},{},{}\n", csv_field(run.scenario.name), csv_field(r.simulator), k,
                               csv_number(a.t), csv_number(a.height), alpha, beta);
            }
        }
    }
    return text;
}

WrittenFiles write_reports(const RunReport& report, const std::filesystem::path& out_dir, const RunVerdict* verdict) {
    WrittenFiles written = {"report.json", "report.md", "junit.xml", "bounces.csv"};
    OutputWrites writes;  // one report that cannot be written costs only itself
    writes.attempt([&] { write_file_atomically(out_dir / "report.json", json_text(to_json(report), 2) + "\n"); });
    writes.attempt([&] { write_file_atomically(out_dir / "report.md", to_markdown(report, verdict)); });
    writes.attempt([&] { write_file_atomically(out_dir / "junit.xml", to_junit(report)); });
    writes.attempt([&] { write_file_atomically(out_dir / "bounces.csv", bounces_csv(report)); });
    const bool plotted = std::any_of(report.scenarios.begin(), report.scenarios.end(),
                                     [](const ScenarioRun& run) { return !run.plots.empty(); });
    if (plotted) {
        writes.attempt([&] { write_page(out_dir / "report.html", to_html(report)); });
        written.push_back("report.html");
    }
    writes.finish();
    // The trajectories the run wrote as it streamed (--trajectories) are its output too.
    for (const ScenarioRun& run : report.scenarios)
        for (const SimulatorSummary& r : run.results)
            if (!r.trajectory_file.empty()) written.push_back(r.trajectory_file);
    return written;
}

}  // namespace bouncecheck
