// The run reports: report.json, the terminal comparison table, report.md,
// junit.xml and bounces.csv, on a RunReport built by hand.
#include "platform/program.h"
#include "reports/provenance.h"
#include "reports/run_report.h"
#include "verdicts/ranking.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <unistd.h>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {
namespace {

// The commit this test's build was made from, as git names it now; empty
// without git or a checkout.
std::string source_head() {
    const std::string root = std::filesystem::path(BOUNCECHECK_SCENARIO_DIR).parent_path().string();
    if (!std::filesystem::exists(root + "/.git")) return "";
    std::string head;
    ProgramRequest git;
    git.argv = {"git", "-C", root, "rev-parse", "HEAD"};
    git.on_output = [&](std::string_view piece) {
        head += piece;
        return true;
    };
    if (!run_program(git).succeeded()) return "";
    while (!head.empty() && (head.back() == '\n' || head.back() == '\r')) head.pop_back();
    return head;
}

const double kNaN = std::numeric_limits<double>::quiet_NaN();

Scenario test_scenario() {
    Scenario s;
    s.name = "seed-3d";
    s.dim = 3;
    s.dt = 0.03;
    s.duration = 42.0;
    s.thresholds.all.bounce_height_rel = 0.05;
    s.thresholds.simulator["bullet"].trajectory_rms = 0.01;
    return s;
}

Divergence divergence(const std::string& baseline, double rel_max, double rms) {
    Divergence d;
    d.baseline = baseline;
    d.bounces.push_back(BounceDiff{0, 0.70, 0.70, 0.0, 0.0, 4.0, 4.0});
    d.bounces.push_back(BounceDiff{1, 0.50 * (1 + rel_max), 0.50, 0.5 * rel_max, rel_max, 6.0, std::nullopt});
    d.bounce_height_rel_max = rel_max;
    d.contact_time_max = 0.0;  // bounce 0's contacts agree; bounce 1 has no baseline contact
    d.apexes_self = 2;
    d.apexes_baseline = 2;
    d.note = "compared the first 2 apexes";
    d.trajectory.samples = 1400;
    d.trajectory.rms = rms;
    d.trajectory.max = 2 * rms;
    d.trajectory.rms_before_rest = rms;
    d.trajectory.max_before_rest = 2 * rms;
    return d;
}

SimulatorSummary reference_summary() {
    SimulatorSummary r;
    r.simulator = "reference";
    r.steps = 1400;
    r.contacts = 5;
    r.floor_contacts = 3;
    r.apexes = {{2.04, 0.70}, {5.0, 0.50}};
    r.apex_count = 2;
    r.contact_events = {
        {1.0, 2, -1, 0.70, 0.99},  // before the first apex: ends no kept bounce
        {3.0, 0, -1, 0.80, 0.99},  // a side wall
        {3.5, 2, +1, 0.50, 0.99},  // the ceiling
        {4.0, 2, -1, 0.81, 0.98},  // ends bounce 0
        {6.0, 2, -1, 0.79, kNaN},  // ends bounce 1; no tangential motion
    };
    r.run_seconds = 1.4e-5;  // 10 ns per step
    return r;
}

Comparison reference_comparison() {
    Comparison c;
    c.vs_reference = divergence("reference", 0.0, 0.0);
    c.vs_exact = divergence("exact", 0.001, 1.5e-6);
    c.vs_exact.contact_time_max = 0.03;  // within 1 cm of exact over the whole run: no first_exceeds
    c.damping.contacts = 4;
    c.damping.tangential_contacts = 3;
    c.damping.normal_mean = 0.8;
    c.damping.normal_worst = 0.81;
    c.damping.tangential_mean = 0.99;
    c.damping.tangential_worst = 0.98;
    c.damping.reproduces = true;
    c.damping.verdict = "reproduces the damping law";
    c.thresholds.push_back({"bounce_height_rel", 0.0, 0.05, true});
    return c;
}

SimulatorSummary bullet_summary() {
    SimulatorSummary r;
    r.simulator = "bullet";
    r.steps = 1400;
    r.contacts = 4;
    r.floor_contacts = 2;
    r.apexes = {{2.05, 0.71}, {5.1, 0.52}};
    r.apex_count = 2;
    r.contact_events = {{4.1, 2, -1, 0.75, 0.97}};  // the second apex has no contact after it
    r.run_seconds = 1.75e-4;                        // 125 ns per step
    return r;
}

Comparison bullet_comparison() {
    Comparison c;
    c.vs_reference = divergence("reference", 0.04, 0.0123);
    c.vs_exact = divergence("exact", 0.041, 0.0125);
    c.vs_exact.trajectory.max = std::numeric_limits<double>::infinity();  // written as null
    c.vs_exact.contact_time_max = 0.1;
    c.vs_exact.trajectory.first_exceeds = 2.52;
    c.damping.contacts = 2;
    c.damping.tangential_contacts = 0;
    c.damping.normal_mean = 0.75;
    c.damping.normal_worst = 0.75;
    c.damping.reproduces = false;
    c.damping.verdict = "normal coefficient 0.75 differs from alpha 0.8";
    c.thresholds.push_back({"bounce_height_rel", 0.04, 0.05, true});
    c.thresholds.push_back({"trajectory_rms", 0.0123, 0.01, false});
    return c;
}

SimulatorSummary skipped_summary(const std::string& reason) {
    SimulatorSummary r;
    r.simulator = "ode";
    r.status = RunStatus::skipped;
    r.reason = reason;
    return r;
}

RunReport test_report() {
    ScenarioRun run;
    run.scenario = test_scenario();
    run.results = {reference_summary(), bullet_summary(), skipped_summary("needs <libode> & \"double\" 'ok'")};
    run.comparisons = {reference_comparison(), bullet_comparison(), std::nullopt};
    RunReport report;
    report.scenarios = {run};
    return report;
}

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
    return n;
}

// Columns on a terminal: code points, ANSI escapes excluded.
std::size_t visible_columns(const std::string& line) {
    const std::string plain = std::regex_replace(line, std::regex("\x1b\\[[0-9;]*m"), "");
    std::size_t n = 0;
    for (unsigned char ch : plain)
        if ((ch & 0xc0) != 0x80) ++n;
    return n;
}

TEST(ReportsJson, HasComparisonFieldsAndParses) {
    const std::string text = to_json(test_report()).dump(2);
    const nlohmann::json j = nlohmann::json::parse(text);  // throws if invalid
    EXPECT_EQ(j["schema"], "bouncecheck-report/1");
    const auto& scenario = j["scenarios"][0];
    EXPECT_DOUBLE_EQ(scenario["scenario"]["thresholds"]["all"]["bounce_height_rel"].get<double>(), 0.05);
    EXPECT_FALSE(scenario["scenario"]["thresholds"]["all"].contains("trajectory_rms"));
    EXPECT_DOUBLE_EQ(scenario["scenario"]["thresholds"]["simulators"]["bullet"]["trajectory_rms"].get<double>(), 0.01);
    EXPECT_EQ(scenario["scenario"]["thresholds"]["simulators"]["bullet"].size(), 1u);

    const auto& bullet = scenario["simulators"][1];
    ASSERT_EQ(bullet["simulator"], "bullet");
    const auto& c = bullet["comparison"];
    EXPECT_EQ(c["vs_reference"]["baseline"], "reference");
    EXPECT_EQ(c["vs_exact"]["baseline"], "exact");
    ASSERT_EQ(c["vs_reference"]["bounces"].size(), 2u);
    const auto& b1 = c["vs_reference"]["bounces"][1];
    for (const char* key : {"index", "height", "baseline_height", "abs_diff", "rel_diff", "contact_t"})
        EXPECT_TRUE(b1.contains(key)) << key;
    EXPECT_TRUE(b1["baseline_contact_t"].is_null());
    EXPECT_DOUBLE_EQ(c["vs_reference"]["bounce_height_rel_max"].get<double>(), 0.04);
    EXPECT_EQ(c["vs_reference"]["apexes_self"], 2);
    EXPECT_EQ(c["vs_reference"]["note"], "compared the first 2 apexes");
    const auto& t = c["vs_reference"]["trajectory"];
    EXPECT_EQ(t["samples"], 1400);
    EXPECT_DOUBLE_EQ(t["rms"].get<double>(), 0.0123);
    EXPECT_TRUE(t["rest_cut"].is_null());
    EXPECT_TRUE(t["first_exceeds"].is_null());
    for (const char* key : {"max", "rms_before_rest", "max_before_rest", "tolerance"}) EXPECT_TRUE(t.contains(key));
    EXPECT_TRUE(c["vs_exact"]["trajectory"]["max"].is_null());  // infinity
    EXPECT_DOUBLE_EQ(c["vs_exact"]["contact_time_max"].get<double>(), 0.1);
    EXPECT_DOUBLE_EQ(c["vs_exact"]["trajectory"]["first_exceeds"].get<double>(), 2.52);
    EXPECT_EQ(c["damping"]["verdict"], "normal coefficient 0.75 differs from alpha 0.8");
    EXPECT_EQ(c["damping"]["reproduces"], false);
    EXPECT_EQ(c["damping"]["tangential_contacts"], 0);
    ASSERT_EQ(c["thresholds"].size(), 2u);
    EXPECT_EQ(c["thresholds"][1]["metric"], "trajectory_rms");
    EXPECT_DOUBLE_EQ(c["thresholds"][1]["measured"].get<double>(), 0.0123);
    EXPECT_DOUBLE_EQ(c["thresholds"][1]["limit"].get<double>(), 0.01);
    EXPECT_EQ(c["thresholds"][1]["passed"], false);
    EXPECT_TRUE(c["passed"].is_boolean());

    const auto& contacts = scenario["simulators"][0]["contacts_measured"];
    ASSERT_EQ(contacts.size(), 5u);
    EXPECT_EQ(contacts[2]["axis"], 2);
    EXPECT_EQ(contacts[2]["side"], 1);
    EXPECT_DOUBLE_EQ(contacts[3]["normal_coefficient"].get<double>(), 0.81);
    EXPECT_TRUE(contacts[4]["tangential_retention"].is_null());

    const auto& skipped = scenario["simulators"][2];
    EXPECT_EQ(skipped["status"], "skipped");
    EXPECT_FALSE(skipped.contains("comparison"));
}

TEST(ReportsJson, ContactsMeasuredLimitedTo200) {
    RunReport report = test_report();
    auto& events = report.scenarios[0].results[0].contact_events;
    events.resize(300, ContactEvent{9.0, 2, -1, 0.8, 0.99});
    const nlohmann::json j = to_json(report);
    EXPECT_EQ(j["scenarios"][0]["simulators"][0]["contacts_measured"].size(), 200u);
}

TEST(ReportsJunit, CountsAndFailureMessage) {
    const std::string xml = to_junit(test_report());
    EXPECT_EQ(xml.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n", 0), 0u);
    // reference: 1 threshold; bullet: 2 thresholds (1 failed); ode: "run", skipped.
    EXPECT_NE(xml.find("<testsuites name=\"bouncecheck\" tests=\"4\" failures=\"1\" errors=\"0\" skipped=\"1\">"),
              std::string::npos);
    EXPECT_NE(xml.find("<testsuite name=\"seed-3d\" tests=\"4\" failures=\"1\" errors=\"0\" skipped=\"1\">"),
              std::string::npos);
    EXPECT_EQ(count(xml, "<testcase "), 4u);
    EXPECT_EQ(count(xml, "<failure "), 1u);
    EXPECT_EQ(count(xml, "<skipped "), 1u);
    EXPECT_NE(xml.find("<testcase classname=\"seed-3d.bullet\" name=\"trajectory_rms\">"), std::string::npos);
    EXPECT_NE(xml.find("<testcase classname=\"seed-3d.ode\" name=\"run\">"), std::string::npos);

    const std::size_t at = xml.find("<failure message=\"");
    ASSERT_NE(at, std::string::npos);
    const std::size_t begin = at + std::string("<failure message=\"").size();
    const std::string message = xml.substr(begin, xml.find('"', begin) - begin);
    EXPECT_EQ(message, "bullet: trajectory_rms = 0.0123 exceeds limit 0.01");
    EXPECT_EQ(count(xml, "<testsuite "), 1u);
    EXPECT_NE(xml.find("</testsuites>"), std::string::npos);
}

TEST(ReportsJunit, FailedRunWithoutThresholds) {
    RunReport report = test_report();
    report.scenarios[0].results[0].status = RunStatus::failed;
    report.scenarios[0].results[0].reason = "ball left the room";
    report.scenarios[0].comparisons[0]->thresholds.clear();
    const std::string xml = to_junit(report);
    EXPECT_NE(xml.find("<testsuite name=\"seed-3d\" tests=\"4\" failures=\"2\" errors=\"0\" skipped=\"1\">"),
              std::string::npos);
    EXPECT_NE(xml.find("<failure message=\"reference: FAILED: ball left the room\">"), std::string::npos);
}

TEST(ReportsJunit, EscapesXmlText) {
    const std::string xml = to_junit(test_report());
    EXPECT_NE(xml.find("<skipped message=\"needs &lt;libode&gt; &amp; &quot;double&quot; &apos;ok&apos;\"/>"),
              std::string::npos)
        << xml;
    EXPECT_EQ(xml.find("<libode>"), std::string::npos);
    EXPECT_EQ(xml.find("& "), std::string::npos);

    RunReport report = test_report();
    report.scenarios[0].scenario.name = "a<b>&\"c'";
    const std::string escaped = to_junit(report);
    EXPECT_NE(escaped.find("<testsuite name=\"a&lt;b&gt;&amp;&quot;c&apos;\""), std::string::npos);
    EXPECT_NE(escaped.find("classname=\"a&lt;b&gt;&amp;&quot;c&apos;.bullet\""), std::string::npos);
}

TEST(ReportsMarkdown, TableAndFailedThreshold) {
    const std::string md = to_markdown(test_report());
    EXPECT_NE(md.find("## seed-3d (3D, dt = 0.03 s, duration = 42 s)"), std::string::npos);
    EXPECT_NE(md.find("| simulator | steps | contacts | first apex heights (m) | rest (s) | run time | ns/step |"),
              std::string::npos);
    EXPECT_NE(md.find("| simulator | apex err | contact err | rms<rest | tracks exact | apex div | alpha | beta | "
                      "damping | thresholds |"),
              std::string::npos);
    EXPECT_NE(md.find("- bullet: `trajectory_rms` = 0.0123 > 0.01"), std::string::npos);
    EXPECT_NE(md.find("- bullet: normal coefficient 0.75 differs from alpha 0.8"), std::string::npos);
}

TEST(ReportsCsv, OneRowPerApexWithTheContactEndingIt) {
    const std::vector<std::string> lines = lines_of(bounces_csv(test_report()));
    ASSERT_EQ(lines.size(), 5u);  // header + 2 reference + 2 bullet apexes; the skipped one has none
    EXPECT_EQ(lines[0], "scenario,simulator,bounce,t,apex,measured_alpha,measured_beta");
    EXPECT_EQ(lines[1], "seed-3d,reference,0,2.04,0.69999999999999996,0.81000000000000005,0.97999999999999998");
    EXPECT_EQ(lines[2], "seed-3d,reference,1,5,0.5,0.79000000000000004,");  // NaN beta: empty
    EXPECT_EQ(lines[3], "seed-3d,bullet,0,2.0499999999999998,0.70999999999999996,0.75,0.96999999999999997");
    EXPECT_EQ(lines[4], "seed-3d,bullet,1,5.0999999999999996,0.52000000000000002,,");  // no contact after
}

TEST(ReportsTerminal, FitsHundredColumnsWithoutColour) {
    RunReport report = test_report();
    SimulatorSummary failed = bullet_summary();
    failed.simulator = "box2d-with-a-long-name";
    failed.status = RunStatus::failed;
    failed.reason = std::string(40, 'x') + " " + std::string(130, 'y') + " and then some more words of explanation "
                    "that keep going on for a while past the edge";
    report.scenarios[0].results.push_back(failed);
    report.scenarios[0].comparisons.push_back(bullet_comparison());
    report.scenarios[0].results[2].reason = std::string(200, 'r');

    for (bool colour : {false, true}) {
        const std::string text = format_run(report, colour);
        EXPECT_EQ(text.find('\x1b') != std::string::npos, colour);
        for (const std::string& line : lines_of(text)) EXPECT_LE(visible_columns(line), 100u) << line;
        EXPECT_NE(text.find("FAILED: xxxx"), std::string::npos);
        EXPECT_NE(text.find("skipped: rrrr"), std::string::npos);
    }
    const std::string plain = format_run(report, false);
    EXPECT_NE(plain.find("trajectory_rms = 0.0123 > 0.01"), std::string::npos);
    EXPECT_NE(plain.find("FAIL 1"), std::string::npos);
    EXPECT_NE(plain.find("DIFFERS"), std::string::npos);
}

TEST(ReportsTerminal, OneBlockPerScenarioSummaryThenComparisonThenRanking) {
    const std::vector<std::string> lines = lines_of(format_run(test_report(), false));
    const std::vector<std::string> expected = {
        "",
        "seed-3d (3D, dt = 0.03 s, duration = 42 s)",
        "  simulator     steps  contacts  first apex heights (m)          rest (s)   run time   ns/step",
        "  reference      1400         5  0.7000 0.5000                          -    0.014ms      10.0",
        "  bullet         1400         4  0.7100 0.5200                          -    0.175ms     125.0",
        "  ode       skipped: needs <libode> & \"double\" 'ok'",
        "",
        "  simulator apex err contact err  rms<rest tracks exact apex div  alpha   beta damping thresholds",
        "  reference    0.10%      0.03 s 1.5e-06 m    whole run    0.00% 0.8000 0.9900      ok       pass",
        "  bullet       4.10%       0.1 s  0.0125 m       2.52 s    4.00% 0.7500      - DIFFERS     FAIL 1",
        "      trajectory_rms = 0.0123 > 0.01",
        "  ode       skipped",
        // The baselines are not ranked: bullet is the only engine.
        "  closest to exact: apex heights bullet (4.10%), contact times bullet (0.1 s), tracks longest bullet",
        "    (2.52 s); closest to the reference: bullet (4.00%)",
    };
    EXPECT_EQ(lines, expected);
}

TEST(ReportsTerminal, FailedRowShowsOnlyItsFailure) {
    RunReport report = test_report();
    report.scenarios[0].results[1].status = RunStatus::failed;  // bullet, with its comparison still attached
    report.scenarios[0].results[1].reason = "external exited with status 1";
    const std::string text = format_run(report, false);
    const std::vector<std::string> lines = lines_of(text);
    EXPECT_NE(std::find(lines.begin(), lines.end(), "  bullet    FAILED: external exited with status 1"), lines.end())
        << text;
    EXPECT_NE(std::find(lines.begin(), lines.end(), "  bullet    FAILED"), lines.end()) << text;
    // None of its partial figures, verdicts or threshold lines, and it ranks nothing.
    for (const char* figure : {"4.10%", "0.0125 m", "DIFFERS", "FAIL 1", "trajectory_rms", "0.7100", "closest"})
        EXPECT_EQ(text.find(figure), std::string::npos) << figure << "\n" << text;
    const std::string md = to_markdown(report);
    EXPECT_NE(md.find("| bullet | **FAILED** |"), std::string::npos) << md;
    EXPECT_EQ(md.find("4.10%"), std::string::npos) << md;
}

TEST(ReportsTerminal, ExactAgainstItselfRanksNothing) {
    RunReport report = test_report();
    SimulatorSummary exact = reference_summary();
    exact.simulator = "exact";
    Comparison c = reference_comparison();
    c.vs_exact = divergence("exact", 0.0, 0.0);
    report.scenarios[0].results = {exact};
    report.scenarios[0].comparisons = {c};
    const std::vector<std::string> lines = lines_of(format_run(report, false));
    ASSERT_EQ(lines.size(), 7u);  // heading, 2 summary lines with the fill note, blank, 2 rows: no ranking line
    EXPECT_EQ(lines[6], "  exact            -           -         -            -    0.00% 0.8000 0.9900      ok       pass");
}

TEST(ReportsVerdict, SaysTheExitStatusAndWhy) {
    RunReport report = test_report();
    RunVerdict verdict = run_verdict(report);
    EXPECT_TRUE(verdict.failed.empty());
    EXPECT_EQ(verdict.exceeded, std::vector<std::string>{"bullet on seed-3d"});
    EXPECT_EQ(verdict.damping_differs, std::vector<std::string>{"bullet on seed-3d"});
    verdict.exit_status = 1;
    const std::vector<std::string> lines = lines_of(format_verdict(verdict));
    ASSERT_GE(lines.size(), 2u);
    EXPECT_EQ(lines[0], "verdict: one run exceeded a threshold (bullet on seed-3d) (exit 1)");
    EXPECT_EQ(lines[1].rfind("note: the measured damping differs from the law for bullet on seed-3d", 0), 0u);

    report.scenarios[0].results[0].status = RunStatus::failed;
    verdict = run_verdict(report, /*baseline_changed=*/true);
    verdict.exit_status = 3;
    EXPECT_EQ(lines_of(format_verdict(verdict))[0],
              "verdict: 1 simulator run failed (reference on seed-3d); the other results are written; one run");
    for (const std::string& line : lines_of(format_verdict(verdict))) EXPECT_LE(visible_columns(line), 100u) << line;
    EXPECT_NE(format_verdict(verdict).find("changed from the baseline"), std::string::npos);

    RunReport clean = test_report();
    clean.scenarios[0].comparisons[1]->thresholds.clear();
    clean.scenarios[0].comparisons[1]->damping.reproduces = true;
    verdict = run_verdict(clean);
    EXPECT_EQ(format_verdict(verdict), "verdict: every simulator ran and every threshold held (exit 0)\n");
    // report.md ends with it.
    const std::string md = to_markdown(clean, &verdict);
    EXPECT_EQ(md.substr(md.size() - 68), "\n**verdict: every simulator ran and every threshold held (exit 0)**\n");
}

TEST(ReportsGolden, Markdown) {
    const std::string expected = R"(# bouncecheck report

## seed-3d (3D, dt = 0.03 s, duration = 42 s)

| simulator | steps | contacts | first apex heights (m) | rest (s) | run time | ns/step |
| :-- | --: | --: | :-- | --: | --: | --: |
| reference | 1400 | 5 | 0.7000 0.5000 | - | 0.014ms | 10.0 |
| bullet | 1400 | 4 | 0.7100 0.5200 | - | 0.175ms | 125.0 |
| ode | skipped: needs <libode> & "double" 'ok' |  |  |  |  |  |

| simulator | apex err | contact err | rms<rest | tracks exact | apex div | alpha | beta | damping | thresholds |
| :-- | --: | --: | --: | --: | --: | --: | --: | :-- | :-- |
| reference | 0.10% | 0.03 s | 1.5e-06 m | whole run | 0.00% | 0.8000 | 0.9900 | ok | pass |
| bullet | 4.10% | 0.1 s | 0.0125 m | 2.52 s | 4.00% | 0.7500 | - | **DIFFERS** | **FAIL 1** |
| ode | skipped |  |  |  |  |  |  |  |  |

closest to exact: apex heights bullet (4.10%), contact times bullet (0.1 s), tracks longest bullet (2.52 s); closest to the reference: bullet (4.00%)

Failures:

- bullet: `trajectory_rms` = 0.0123 > 0.01

Damping:

- reference: reproduces the damping law
- bullet: normal coefficient 0.75 differs from alpha 0.8
)";
    EXPECT_EQ(to_markdown(test_report()), expected);
}

TEST(ReportsWrite, WritesTheFourFiles) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("bouncecheck-reports-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const RunReport report = test_report();
    write_reports(report, dir);
    auto read = [&](const char* name) {
        std::ifstream in(dir / name, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    EXPECT_EQ(read("report.json"), to_json(report).dump(2) + "\n");
    EXPECT_EQ(read("report.md"), to_markdown(report));
    EXPECT_EQ(read("junit.xml"), to_junit(report));
    EXPECT_EQ(read("bounces.csv"), bounces_csv(report));
    std::filesystem::remove_all(dir);
}

// The provenance names the commit the binary was built from: read at build
// time (cmake/git_state.cmake), so a build after a commit names the new one.
// It held the configure-time commit before. (A test run against a binary
// older than the checked-out commit fails here, which is the point.)
TEST(Provenance, NamesTheCommitTheBinaryWasBuiltFrom) {
    const std::string head = source_head();
    if (head.empty()) GTEST_SKIP() << "not built from a git checkout, or no git";
    EXPECT_EQ(this_provenance(false).build.git_commit, head);
}

TEST(Ranking, EnginesOnlyTiesTogetherFailedLeftOut) {
    RunReport report = test_report();
    ScenarioRun& run = report.scenarios[0];
    // A second engine tied with bullet on apex heights, better on contact times, never leaving exact's band.
    SimulatorSummary twin = run.results[1];
    twin.simulator = "twin";
    Comparison twin_c = *run.comparisons[1];
    twin_c.vs_exact.contact_time_max = 0.01;
    twin_c.vs_exact.trajectory.first_exceeds.reset();
    run.results.push_back(twin);
    run.comparisons.push_back(twin_c);
    // A failed engine with the best figures of all ranks nothing.
    SimulatorSummary broken = run.results[1];
    broken.simulator = "broken";
    broken.status = RunStatus::failed;
    Comparison broken_c = *run.comparisons[1];
    broken_c.vs_exact.bounce_height_rel_max = 0;
    broken_c.vs_reference.bounce_height_rel_max = 0;
    run.results.push_back(broken);
    run.comparisons.push_back(broken_c);

    const ScenarioRanking r = rank_simulators(run.results, run.comparisons);
    ASSERT_TRUE(r.apex_error && r.contact_error && r.tracks_exact && r.apex_divergence);
    EXPECT_EQ(r.apex_error->simulators, (std::vector<std::string>{"bullet", "twin"}));  // the reference's 0.10% is not ranked
    EXPECT_EQ(r.contact_error->simulators, std::vector<std::string>{"twin"});
    EXPECT_DOUBLE_EQ(r.contact_error->value, 0.01);
    EXPECT_EQ(r.tracks_exact->simulators, std::vector<std::string>{"twin"});
    EXPECT_TRUE(r.tracks_exact->whole_run);
    EXPECT_EQ(r.apex_divergence->simulators, (std::vector<std::string>{"bullet", "twin"}));

    const nlohmann::json j = to_json(report)["scenarios"][0]["ranking"];
    EXPECT_EQ(j["contact_error"]["simulators"], nlohmann::json::array({"twin"}));
    EXPECT_TRUE(j["tracks_exact"]["value"].is_null());  // the whole run
    EXPECT_EQ(j["apex_error"]["simulators"], nlohmann::json::array({"bullet", "twin"}));
}

TEST(Ranking, NothingToRankWithoutAnEngine) {
    RunReport report = test_report();
    report.scenarios[0].results.resize(1);  // the reference only
    report.scenarios[0].comparisons.resize(1);
    EXPECT_TRUE(rank_simulators(report.scenarios[0].results, report.scenarios[0].comparisons).empty());
    EXPECT_TRUE(to_json(report)["scenarios"][0]["ranking"]["apex_error"].is_null());
}

}  // namespace
}  // namespace bouncecheck
