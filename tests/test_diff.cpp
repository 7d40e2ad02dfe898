// `bouncecheck diff` and `run --baseline`: what changed between two runs,
// beyond tolerance; and the provenance every report carries.
#include "commands/diff/diff_pipeline.h"
#include "registry/registry.h"
#include "reports/provenance.h"
#include "tests/support/cli.h"
#include "tests/support/test_directory.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>
#include <variant>

namespace fs = std::filesystem;

namespace bouncecheck {
namespace {

using json = nlohmann::json;
using test::bouncecheck;
using test::CliResult;
using test::slurp;

const std::string kScenarios = BOUNCECHECK_SCENARIO_DIR;

// A small report of the current schema: one scenario, one simulator.
json report(double apex_height = 0.5, const std::string& friction = "0.1") {
    return {{"schema", "bouncecheck-report/1"},
            {"scenarios",
             {{{"scenario", {{"name", "s"}}},
               {"simulators",
                {{{"simulator", "a"},
                  {"status", "ok"},
                  {"steps", 10},
                  {"apexes", {{{"t", 1.0}, {"height", apex_height}}}},
                  {"comparison",
                   {{"vs_reference", {{"trajectory", {{"rms", 0.01}, {"max", 0.02}}}}},
                    {"damping", {{"normal_mean", 0.8}, {"tangential_mean", 0.99}, {"verdict", "reproduces"}}},
                    {"thresholds", {{{"metric", "trajectory_rms"}, {"passed", true}}}}}},
                  {"settings", {{{"key", "friction"}, {"value", friction}, {"why", ""}}}},
                  {"run_seconds", 0.01}}}}}}}};
}

ReportDiff diff(const json& a, const json& b, DiffTolerances t = {}, std::optional<double> ratio = {}) {
    return diff_reports(LoadedReport{a, "old.json"}, LoadedReport{b, "new.json"}, t, ratio);
}

TEST(Diff, IdenticalReportsHaveNoChange) {
    const ReportDiff d = diff(report(), report());
    EXPECT_FALSE(d.changed());
    EXPECT_TRUE(d.changes.empty());
    ASSERT_EQ(d.timings.size(), 1u);
    EXPECT_EQ(d.timings[0].ratio, 1.0);
    EXPECT_FALSE(d.timings[0].regression);  // no --timing-ratio: reported, not judged
}

// A numeric field holding something else (a hand-edited report) is the same
// value on both sides: no change. Found by fuzzing diff's reader (diffing a
// report with itself showed "x -> x" and exited 1); a real change still shows.
TEST(Diff, ANonNumberInANumericFieldIsUnchangedWhenEqual) {
    json a = report(), b = report();
    a["scenarios"][0]["simulators"][0]["apexes"][0]["height"] = "x";
    b["scenarios"][0]["simulators"][0]["apexes"][0]["height"] = "x";
    EXPECT_FALSE(diff(a, b).changed());
    b["scenarios"][0]["simulators"][0]["apexes"][0]["height"] = 0.5;
    ASSERT_EQ(diff(a, b).changes.size(), 1u);
    EXPECT_EQ(diff(a, b).changes[0].metric, "apex[1].height");
}

TEST(Diff, AChangeCountsBeyondItsToleranceOnly) {
    const ReportDiff d = diff(report(0.5), report(0.5 + 1e-6));
    ASSERT_EQ(d.changes.size(), 1u);
    EXPECT_EQ(d.changes[0].simulator, "a");
    EXPECT_EQ(d.changes[0].metric, "apex[1].height");
    EXPECT_EQ(d.changes[0].tolerance_key, "height");
    EXPECT_NEAR(*d.changes[0].delta, 1e-6, 1e-15);

    DiffTolerances loose;
    ASSERT_FALSE(parse_tolerance("height=1e-5", loose));
    EXPECT_FALSE(diff(report(0.5), report(0.5 + 1e-6), loose).changed());
    EXPECT_TRUE(diff(report(0.5), report(0.5 + 2e-5), loose).changed());
}

TEST(Diff, SettingsAndVerdictsCountAnyChange) {
    json b = report(0.5, "0.2");
    b["scenarios"][0]["simulators"][0]["comparison"]["thresholds"][0]["passed"] = false;
    b["scenarios"][0]["simulators"][0]["comparison"]["damping"]["verdict"] = "alpha differs";
    const ReportDiff d = diff(report(), b);
    std::set<std::string> metrics;
    for (const DiffChange& c : d.changes) metrics.insert(c.metric);
    EXPECT_EQ(metrics, (std::set<std::string>{"friction", "threshold trajectory_rms", "damping verdict"}));
    // The setting comes first, and no input of the scenario explains it.
    ASSERT_EQ(d.in(DiffSection::setting).size(), 1u);
    EXPECT_EQ(d.changes[0].section, DiffSection::setting);
    EXPECT_EQ(d.changes[0].cause, "");
    EXPECT_NE(format_diff(d).find("friction  0.1 -> 0.2  (no input changed: the build or the engine did)"),
              std::string::npos)
        << format_diff(d);
}

// The cause first: the inputs as the scenario file writes them, then the
// settings with the input that explains each, then the consequences grouped
// per simulator and kind with a count and the largest change.
TEST(Diff, NamesTheInputsFirstThenTheSettingsThenGroupsTheConsequences) {
    json a = report(0.5), b = report(0.7, "0.2");
    a["scenarios"][0]["scenario"]["alpha"] = 0.8;
    b["scenarios"][0]["scenario"]["alpha"] = 0.7;
    a["scenarios"][0]["scenario"]["engines"] = {{"a", {{"friction", 0.1}}}};
    b["scenarios"][0]["scenario"]["engines"] = {{"a", {{"friction", 0.2}}}};
    for (double h : {0.4, 0.3, 0.2}) {
        a["scenarios"][0]["simulators"][0]["apexes"].push_back({{"t", 2.0}, {"height", h}});
        b["scenarios"][0]["simulators"][0]["apexes"].push_back({{"t", 2.0}, {"height", h - 0.01}});
    }
    b["scenarios"][0]["simulators"][0]["run_seconds"] = 0.02;
    const ReportDiff d = diff(a, b);
    const auto inputs = d.in(DiffSection::input);
    ASSERT_EQ(inputs.size(), 2u);
    EXPECT_EQ(inputs[0]->metric, "[damping] normal");
    EXPECT_EQ(inputs[1]->metric, "[engines.a] friction");
    const auto settings = d.in(DiffSection::setting);
    ASSERT_EQ(settings.size(), 1u);
    EXPECT_EQ(settings[0]->cause, "[engines.a] friction") << "its own engine's table explains it first";
    EXPECT_EQ(d.in(DiffSection::consequence).size(), 4u);  // four apex heights

    const std::string text = format_diff(d);
    const auto at = [&](const std::string& what) { return text.find(what); };
    ASSERT_NE(at("inputs changed (2)"), std::string::npos) << text;
    EXPECT_LT(at("inputs changed"), at("settings changed")) << text;
    EXPECT_LT(at("settings changed"), at("consequences")) << text;
    EXPECT_NE(at("s  [damping] normal  0.8 -> 0.7"), std::string::npos) << text;
    EXPECT_NE(at("(follows [engines.a] friction)"), std::string::npos) << text;
    // One line for the group, with its count and its largest change.
    EXPECT_NE(at("s / a  apex heights: 4 changed; largest apex[1].height 0.5 -> 0.7 (+2.000e-01)"), std::string::npos)
        << text;
    EXPECT_EQ(at("apex[3].height"), std::string::npos) << "not one by one without --all:\n" << text;
    // Timings only when asked for; a count of them otherwise.
    EXPECT_EQ(at("ms ->"), std::string::npos) << text;
    EXPECT_NE(at("1 timing compared, not judged (--timings shows them)"), std::string::npos) << text;

    const std::string all = format_diff(d, {/*all=*/true, /*timings=*/true});
    for (const char* each : {"apex[1].height", "apex[2].height", "apex[3].height", "apex[4].height"})
        EXPECT_NE(all.find(each), std::string::npos) << each << "\n" << all;
    EXPECT_NE(all.find("ms ->"), std::string::npos) << all;
    // diff.md: the sections; diff.json: every change with its section, and the groups.
    const std::string md = diff_markdown(d);
    EXPECT_NE(md.find("## Inputs changed (2)"), std::string::npos) << md;
    EXPECT_NE(md.find("| s | `[damping] normal` | 0.8 | 0.7 |"), std::string::npos) << md;
    EXPECT_NE(md.find("| s / a | apex heights | 4 | apex[1].height |"), std::string::npos) << md;
    const json j = diff_json(d);
    EXPECT_EQ(j["changes"].size(), 7u);
    EXPECT_EQ(j["changes"][0]["section"], "input");
    EXPECT_EQ(j["changes"][2]["section"], "setting");
    EXPECT_EQ(j["changes"][2]["cause"], "[engines.a] friction");
    ASSERT_EQ(j["consequence_groups"].size(), 1u);
    EXPECT_EQ(j["consequence_groups"][0]["count"], 4);
}

TEST(Diff, SimulatorsAndScenariosThatAppearOrDisappear) {
    json b = report();
    b["scenarios"][0]["simulators"].push_back({{"simulator", "new-engine"}, {"status", "ok"}});
    json other = report();
    other["scenarios"][0]["scenario"]["name"] = "t";
    b["scenarios"].push_back(other["scenarios"][0]);
    ReportDiff d = diff(report(), b);
    ASSERT_EQ(d.changes.size(), 2u);
    EXPECT_EQ(d.changes[0].simulator, "new-engine");
    EXPECT_EQ(d.changes[0].old_value, "absent");
    EXPECT_EQ(d.changes[0].new_value, "present");
    EXPECT_EQ(d.changes[1].scenario, "t");
    EXPECT_EQ(d.changes[1].metric, "scenario");

    d = diff(b, report());  // and the other way round
    ASSERT_EQ(d.changes.size(), 2u);
    EXPECT_EQ(d.changes[0].old_value, "present");
    EXPECT_EQ(d.changes[0].new_value, "absent");
}

TEST(Diff, TimingsAreARegressionOnlyAboveTheRatioAsked) {
    json b = report();
    b["scenarios"][0]["simulators"][0]["run_seconds"] = 0.03;
    EXPECT_FALSE(diff(report(), b).changed());
    const ReportDiff d = diff(report(), b, {}, 2.0);
    ASSERT_EQ(d.timings.size(), 1u);
    EXPECT_DOUBLE_EQ(d.timings[0].ratio, 3.0);
    EXPECT_TRUE(d.timings[0].regression);
    EXPECT_TRUE(d.changed());
    EXPECT_FALSE(diff(report(), b, {}, 4.0).changed());
}

TEST(Diff, AReportFromBeforeProvenanceStillDiffs) {
    json with = report();
    with["provenance"] = to_json(this_provenance(true));
    const ReportDiff d = diff(report(), with);
    EXPECT_FALSE(d.changed());
    EXPECT_EQ(d.old_provenance, "unknown (the report has no provenance)");
    EXPECT_NE(d.new_provenance.find("bouncecheck " BOUNCECHECK_VERSION), std::string::npos) << d.new_provenance;
}

class DiffInput : public test::TestDirectory {};

TEST_F(DiffInput, BadInputIsRefusedWithTheReason) {
    const fs::path good = write_file("good.json", report().dump());
    json sweep = {{"schema", "bouncecheck-sweep/1"}};
    json future = report();
    future["schema"] = "bouncecheck-report/2";
    fs::create_directories(dir_ / "empty");
    const struct {
        fs::path path;
        std::string message;
    } cases[] = {
        {dir_ / "missing.json", "no such file"},
        {dir_ / "empty", "holds no report.json"},
        {write_file("text.json", "not json"), "not JSON"},
        {write_file("sweep.json", sweep.dump()), "a sweep report"},
        {write_file("future.json", future.dump()), "schema \"bouncecheck-report/2\", which this bouncecheck cannot read"},
        {write_file("noschema.json", "{\"scenarios\": []}"), "no \"schema\" field"},
        {write_file("noname.json", R"({"schema": "bouncecheck-report/1", "scenarios": [{"simulators": []}]})"),
         "scenarios[0]: no scenario.name"},
        // The hostile audit's findings 9, 10 and 21.
        {write_file("huge-number.json", R"({"schema": "bouncecheck-report/1", "scenarios": [], "x": 1e400})"),
         "not JSON this bouncecheck can read"},
        {write_file("deep.json", std::string(100000, '[') + std::string(100000, ']')), "nested deeper than 64 levels"},
        {write_file("twice.json", R"({"schema": "bouncecheck-report/1", "scenarios": [
             {"scenario": {"name": "s"}, "simulators": []}, {"scenario": {"name": "s"}, "simulators": []}]})"),
         "scenarios[1]: scenario 's' listed twice"},
        {write_file("sim-twice.json", R"({"schema": "bouncecheck-report/1", "scenarios": [
             {"scenario": {"name": "s"}, "simulators": [{"simulator": "a"}, {"simulator": "a"}]}]})"),
         "scenarios[0].simulators[1]: simulator 'a' listed twice"},
    };
    for (const auto& c : cases) {
        const auto loaded = load_run_report(c.path);
        ASSERT_TRUE(std::holds_alternative<std::string>(loaded)) << c.path;
        EXPECT_NE(std::get<std::string>(loaded).find(c.message), std::string::npos) << std::get<std::string>(loaded);
        const CliResult r = bouncecheck("diff " + c.path.string() + " " + good.string() + " --out " + (dir_ / "o").string());
        EXPECT_EQ(r.status, 2) << r.output;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    }
    // Over the size limit (sparse: costs no disk): refused from its size, not read.
    const fs::path huge = write_file("huge.json", "");
    fs::resize_file(huge, kMaxRunReportBytes + 1);
    CliResult big = bouncecheck("diff " + huge.string() + " " + good.string() + " --out " + (dir_ / "o").string());
    EXPECT_EQ(big.status, 2) << big.output;
    EXPECT_NE(big.output.find("over the limit of 67108864 for a report"), std::string::npos) << big.output;
    // A library's message reaches the user without its "[json.exception...]" prefix.
    const CliResult overflow = bouncecheck("diff " + (dir_ / "huge-number.json").string() + " " + good.string());
    EXPECT_EQ(overflow.output.find("[json.exception"), std::string::npos) << overflow.output;
    EXPECT_NE(overflow.output.find("number overflow"), std::string::npos) << overflow.output;
    // Provenance of the wrong shape reads as unknown; it never throws a library's message.
    json odd = report();
    odd["provenance"] = {{"build", 3}};
    json odder = report();
    odder["provenance"] = {{"build", {{"git_dirty", "yes"}}}, {"machine", {{"cores", "two"}}}};
    for (const json& j : {odd, odder}) {
        const fs::path file = write_file("odd.json", j.dump());
        const CliResult r = bouncecheck("diff " + file.string() + " " + good.string() + " --out " + (dir_ / "o").string());
        EXPECT_EQ(r.status, 0) << r.output;
        EXPECT_EQ(r.output.find("type_error"), std::string::npos) << r.output;
    }
    for (const char* arg : {"--tolerance height", "--tolerance speed=1", "--tolerance height=-1"}) {
        const CliResult r = bouncecheck("diff " + good.string() + " " + good.string() + " " + arg);
        EXPECT_EQ(r.status, 2) << arg << "\n" << r.output;
    }
    const CliResult r = bouncecheck("run " + kScenarios + "/seed-3d.toml --engines reference --baseline " +
                                    (dir_ / "missing.json").string() + " --out " + (dir_ / "o").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "o" / "report.json")) << "a bad baseline must stop the run before it starts";
}

// The hostile audit's finding 16: a report is outside bytes; its names,
// reasons and settings reach the terminal and diff.md made printable.
TEST_F(DiffInput, ATerminalEscapeInAReportIsShownNotObeyed) {
    json a = report(), b = report(0.6);
    for (json* j : {&a, &b}) {
        (*j)["scenarios"][0]["scenario"]["name"] = "\x1b[2Jevil\x07";
        (*j)["scenarios"][0]["simulators"][0]["simulator"] = "sim\xc2\x9b" "31m";  // C1 CSI
    }
    b["scenarios"][0]["simulators"][0]["status"] = "failed\x1b[2J";
    const fs::path old_file = write_file("a.json", a.dump()), new_file = write_file("b.json", b.dump());
    const CliResult r = bouncecheck("diff " + old_file.string() + " " + new_file.string() + " --out " + (dir_ / "o").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_EQ(r.output.find('\x1b'), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find('\x07'), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("\xc2\x9b"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\\x1b[2Jevil\\x07"), std::string::npos) << r.output;
    const std::string md = slurp(dir_ / "o" / "diff.md");
    EXPECT_EQ(md.find('\x1b'), std::string::npos);
    EXPECT_NE(md.find("\\x1b[2Jevil"), std::string::npos) << md;
}

// The issue's "done when": two runs of one build and input diff to nothing;
// a changed engine setting is named, with the metrics it moved.
TEST_F(DiffInput, TwoRunsOfTheSameInputDifferInNothingAndAChangedSettingIsNamed) {
    bool bullet = false;
    for (const auto& sim : built_simulators()) bullet = bullet || sim->name() == "bullet";
    const std::string engines = bullet ? "reference,exact,bullet" : "reference,exact";
    const std::string seed = slurp(kScenarios + "/seed-3d.toml");
    const fs::path scenario = write_file("seed-3d.toml", seed);
    const auto run = [&](const std::string& out, const std::string& more) {
        return bouncecheck("run " + scenario.string() + " --engines " + engines + " --out " + (dir_ / out).string() +
                           " " + more);
    };
    const int status = run("a", "").status;  // 0, or 1 if a threshold is exceeded
    ASSERT_TRUE(status == 0 || status == 1);
    ASSERT_EQ(run("b", "").status, status);
    CliResult r = bouncecheck("diff " + (dir_ / "a").string() + " " + (dir_ / "b").string() + " --out " +
                              (dir_ / "d").string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("no change beyond tolerance"), std::string::npos) << r.output;
    const json d = json::parse(slurp(dir_ / "d" / "diff.json"));
    EXPECT_EQ(d["schema"], "bouncecheck-diff/1");
    EXPECT_EQ(d["changed"], false);
    EXPECT_TRUE(d["changes"].empty());
    EXPECT_FALSE(d["timings"].empty());  // reported apart, not judged
    EXPECT_NE(slurp(dir_ / "d" / "diff.md").find("No change beyond tolerance."), std::string::npos);
    // The same through run --baseline, in one step.
    r = run("c", "--baseline " + (dir_ / "a").string());
    EXPECT_EQ(r.status, status) << r.output;  // nothing changed: the thresholds' verdict stands alone
    EXPECT_NE(r.output.find("no change beyond tolerance"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(dir_ / "c" / "diff.md"));

    if (!bullet) GTEST_SKIP() << "Bullet is not built: the changed-setting half needs it";
    const std::string key = "[engines.bullet]\nfriction = ";
    const auto at = seed.find(key);
    ASSERT_NE(at, std::string::npos);
    std::string changed = seed;
    changed.replace(at + key.size(), seed.find('\n', at + key.size()) - at - key.size(), "0.02");
    write_file("seed-3d.toml", changed);
    r = run("e", "--baseline " + (dir_ / "a").string());
    EXPECT_EQ(r.status, 1) << r.output;
    const json e = json::parse(slurp(dir_ / "e" / "diff.json"));
    std::set<std::string> simulators, metrics;
    for (const json& c : e["changes"]) {
        if (c["section"] == "input") continue;  // the scenario's, not a simulator's
        simulators.insert(c["simulator"].get<std::string>());
        metrics.insert(c["metric"].get<std::string>());
    }
    EXPECT_EQ(simulators, std::set<std::string>{"bullet"}) << e.dump(1);
    // The input as the file writes it comes first; then Bullet's key for the ball's mu, with its cause.
    EXPECT_EQ(e["changes"][0]["section"], "input");
    EXPECT_EQ(e["changes"][0]["metric"], "[engines.bullet] friction");
    EXPECT_EQ(e["changes"][0]["new"], "0.02");
    EXPECT_TRUE(metrics.count("ball.friction")) << e.dump(1);
    EXPECT_TRUE(metrics.count("apex[2].height")) << e.dump(1);
    EXPECT_TRUE(metrics.count("trajectory rms vs_reference")) << e.dump(1);
    EXPECT_LT(r.output.find("[engines.bullet] friction"), r.output.find("ball.friction")) << r.output;
    EXPECT_NE(r.output.find("(follows [engines.bullet] friction)"), std::string::npos) << r.output;
    EXPECT_NE(slurp(dir_ / "e" / "diff.md").find("| seed-3d | bullet | ball.friction |"), std::string::npos);
}

TEST_F(DiffInput, ReportsCarryProvenanceAndNoTimingsLeavesTheMachineOut) {
    CliResult r = bouncecheck("run " + kScenarios + "/seed-3d.toml --engines reference --out " + (dir_ / "a").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const json a = json::parse(slurp(dir_ / "a" / "report.json"))["provenance"];
    EXPECT_EQ(a["build"]["bouncecheck_version"], BOUNCECHECK_VERSION);
    EXPECT_FALSE(a["build"]["compiler"].get<std::string>().empty());
    EXPECT_GT(a["machine"]["cores"].get<int>(), 0);
    EXPECT_NE(a["machine"]["command_line"].get<std::string>().find("--engines reference"), std::string::npos);
    EXPECT_NE(slurp(dir_ / "a" / "report.md").find("bouncecheck " BOUNCECHECK_VERSION), std::string::npos);
    r = bouncecheck("run " + kScenarios + "/seed-3d.toml --engines reference --no-timings --out " +
                    (dir_ / "b").string());
    const json b = json::parse(slurp(dir_ / "b" / "report.json"))["provenance"];
    EXPECT_TRUE(b.contains("build"));
    EXPECT_FALSE(b.contains("machine"));
}

}  // namespace
}  // namespace bouncecheck
