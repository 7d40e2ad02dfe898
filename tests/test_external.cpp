// External simulators and imported trajectories (docs/external.md): the
// reader, the loader's [external.<name>], the harness's failure handling and
// clean-up, and both example simulators through `run`, `sweep` and `stress`.
#include "commands/run/run_pipeline.h"
#include "external/external_simulator.h"
#include "external/trajectory_reader.h"
#include "metrics/summary.h"
#include "platform/program.h"
#include "reference/reference_simulator.h"
#include "registry/registry.h"
#include "scenarios/loader.h"
#include "simulators/document_clock.h"
#include "tests/support/cli.h"
#include "tests/support/processes.h"
#include "tests/support/test_directory.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <bit>
#include <cerrno>
#include <limits>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>

namespace fs = std::filesystem;

namespace bouncecheck {
namespace {

using test::bouncecheck;
using test::CliResult;
using test::dead;
using test::slurp;

const std::string kData = BOUNCECHECK_TEST_DATA;
const std::string kScenarios = BOUNCECHECK_SCENARIO_DIR;
const std::string kReplay = kData + "/external/replay.sh";
const std::string kGolden3d = kData + "/seed-3d.csv";  // the reference's seed-3d trajectory
const std::string kPythonExample = BOUNCECHECK_EXAMPLES "/semi_implicit_euler.py";
const std::string kEngineExample = BOUNCECHECK_ENGINE_EXAMPLE;

Scenario seed(const char* name) { return load_scenario(kScenarios + "/" + name + ".toml"); }

std::unique_ptr<const Simulator> replay(const std::string& name, const std::string& mode, double timeout = 600,
                                        const std::string& path = "") {
    std::vector<std::string> argv{kReplay, kGolden3d, mode};
    if (!path.empty()) argv.push_back(path);
    return make_external_simulator(ExternalDeclaration{name, argv}, ExternalLimits{timeout});
}

// The run of `sim` beside the reference, as `bouncecheck run` makes it.
ScenarioRun run_beside_reference(const Scenario& s, std::vector<const Simulator*> sims) {
    static const auto reference = make_reference_simulator();
    sims.insert(sims.begin(), reference.get());
    return run_scenario(s, RunRequest{std::move(sims), fs::temp_directory_path(), false, {}});
}

// ------------------------------------------------ the reader

std::vector<State> read_all(const Scenario& s, std::string_view text, std::size_t piece,
                            std::optional<RowProblem>* problem = nullptr) {
    TrajectoryReader reader(s);
    std::vector<State> states;
    const auto keep = [&](const State& st) {
        states.push_back(st);
        return true;
    };
    bool ok = true;
    for (std::size_t at = 0; ok && at < text.size(); at += piece) ok = reader.feed(text.substr(at, piece), keep);
    if (ok) reader.finish(keep);
    if (problem) *problem = reader.problem();
    return states;
}

TEST(TrajectoryReader, ReadsTheGoldenFileTheSameInAnyPieces) {
    const Scenario s = seed("seed-3d");
    const std::string text = slurp(kGolden3d);
    std::optional<RowProblem> problem;
    const std::vector<State> whole = read_all(s, text, text.size(), &problem);
    ASSERT_FALSE(problem) << problem->format();
    ASSERT_EQ(whole.size(), static_cast<std::size_t>(document_step_count(s.dt, s.duration) + 1));
    EXPECT_EQ(whole.front().p, s.position);
    EXPECT_EQ(whole.front().v, s.velocity);
    for (std::size_t piece : {1u, 7u, 4096u}) {
        const std::vector<State> pieces = read_all(s, text, piece, &problem);
        ASSERT_FALSE(problem) << piece;
        ASSERT_EQ(pieces.size(), whole.size());
        for (std::size_t i = 0; i < whole.size(); ++i) {
            ASSERT_EQ(pieces[i].t, whole[i].t);
            ASSERT_EQ(pieces[i].p, whole[i].p);
            ASSERT_EQ(pieces[i].v, whole[i].v);
        }
    }
}

TEST(TrajectoryReader, AcceptsCrlfAndPlusSignsAnd2d) {
    Scenario s = seed("seed-2d");
    s.duration = 2 * s.dt;  // three rows
    std::optional<RowProblem> problem;
    const auto states =
        read_all(s, "t,x,y,vx,vy\r\n0,+0.5,1e-1,0,0\r\n0.03,0.5,0.1,0,-1E-3\r\n0.06,0.5,0.1,0,0\r\n", 1000, &problem);
    ASSERT_FALSE(problem) << problem->format();
    ASSERT_EQ(states.size(), 3u);
    EXPECT_EQ(states[0].p.x(), 0.5);
    EXPECT_EQ(states[1].v.y(), -1e-3);
    EXPECT_EQ(states[2].t, 0.06);
}

// The hostile audit's finding 13: the line limit held only for a line that
// spanned two reads; a long line whole in the first piece passed.
TEST(TrajectoryReader, TheLineLimitHoldsHoweverTheLineArrives) {
    Scenario s = seed("seed-3d");
    s.duration = 2 * s.dt;
    const std::string text = "t,x,y,z,vx,vy,vz\n" + std::string(60000, '1') + "\n";
    for (std::size_t piece : {std::size_t{3}, std::size_t{65536}, std::size_t{1} << 20}) {
        std::optional<RowProblem> problem;
        read_all(s, text, piece, &problem);
        ASSERT_TRUE(problem) << piece;
        EXPECT_EQ(problem->line, 2) << piece;
        EXPECT_NE(problem->reason.find("a line longer than 4096 bytes"), std::string::npos) << problem->reason;
    }
}

TEST(TrajectoryReader, NamesTheLineFieldAndReason) {
    Scenario s = seed("seed-3d");
    s.duration = 2 * s.dt;
    const std::string h = "t,x,y,z,vx,vy,vz\n", row0 = "0,0.5,0.9,0.5,0,0,0\n";
    const struct {
        std::string text;
        std::int64_t line;
        std::string field, reason;
    } cases[] = {
        {"", 1, "", "no header: the trajectory is empty"},
        {"t,x,y,vx,vy\n" + row0, 1, "", "expected the header 't,x,y,z,vx,vy,vz' (3D scenario), got 't,x,y,vx,vy'"},
        {h + "0,0.5,0.9,0.5,0,0\n", 2, "vz", "missing: the row has 6 fields, expected 7"},
        {h + "0,0.5,0.9,0.5,0,0,0,1\n", 2, "", "more than 7 fields"},
        {h + row0 + "0.03,0.5,0.9,0.5,0,x1,0\n", 3, "vy", "not a number: 'x1'"},
        {h + row0 + "0.03,0.5,0.9,0.5,0,,0\n", 3, "vy", "not a number: ''"},
        {h + row0 + "0.03,0.5,0.9,inf,0,0,0\n", 3, "z", "not finite: inf"},
        {h + row0 + "0.03,0.5,0.9,1e999,0,0,0\n", 3, "z", "out of the range of a double"},
        {h + row0 + "0.06,0.5,0.9,0.5,0,0,0\n", 3, "t", "is not row 1's time on the scenario's clock"},
        {h + row0 + "0.03,0.5,0.9,0.5,0,0,0\n", 4, "", "the trajectory ends after 2 rows; the scenario's clock takes 3"},
        {h + row0 + "0.03,0.5,0.9,0.5,0,0,0\n0.06,0.5,0.9,0.5,0,0,0\n0.09,0.5,0.9,0.5,0,0,0\n", 5, "",
         "more rows than the 3"},
        {h + std::string(5000, '1') + "\n", 2, "", "a line longer than 4096 bytes"},
        // The hostile audit's finding 19: a stream cut mid-row still leaves a number.
        {h + row0 + "0.03,0.5,0.9,0.5,0,0,0\n0.06,0.5,0.9,0.5,0,0,0.12", 4, "",
         "the last line has no newline at its end: cut off?"},
    };
    for (const auto& c : cases) {
        std::optional<RowProblem> problem;
        read_all(s, c.text, 3, &problem);
        ASSERT_TRUE(problem) << c.text;
        EXPECT_EQ(problem->line, c.line) << c.text;
        EXPECT_EQ(problem->field, c.field) << c.text;
        EXPECT_NE(problem->reason.find(c.reason), std::string::npos) << problem->reason;
    }
}

// The optional #end line after the last row (docs/external.md, Output):
// the program's own measure of its engine's steps; keys of later versions
// ignored; anything malformed, early or followed by more, refused.
TEST(TrajectoryReader, TheEndLineCarriesTheProgramsStepTime) {
    Scenario s = seed("seed-3d");
    s.duration = 2 * s.dt;
    const std::string rows = "t,x,y,z,vx,vy,vz\n0,0.5,0.9,0.5,0,0,0\n0.03,0.5,0.9,0.5,0,0,0\n0.06,0.5,0.9,0.5,0,0,0\n";
    const auto step_seconds = [&](const std::string& text, std::optional<RowProblem>* problem) {
        TrajectoryReader reader(s);
        const auto keep = [](const State&) { return true; };
        for (std::size_t at = 0; at < text.size(); at += 5)
            if (!reader.feed(std::string_view(text).substr(at, 5), keep)) break;
        if (!reader.problem()) reader.finish(keep);
        *problem = reader.problem();
        return reader.step_seconds();
    };
    std::optional<RowProblem> problem;
    EXPECT_FALSE(step_seconds(rows + "#end\n", &problem));
    EXPECT_FALSE(problem) << problem->format();
    EXPECT_EQ(step_seconds(rows + "#end {\"step_seconds\": 0.25, \"later\": {\"a\": 1}}\r\n", &problem), 0.25);
    EXPECT_FALSE(problem) << problem->format();
    EXPECT_FALSE(step_seconds(rows, &problem));  // still optional
    EXPECT_FALSE(problem);

    const struct {
        std::string text;
        std::int64_t line;
        std::string field, reason;
    } cases[] = {
        {rows + "#end {\"step_seconds\": -1}\n", 5, "step_seconds", "must be a finite number of seconds >= 0, got '-1'"},
        {rows + "#end {\"step_seconds\": \"1\"}\n", 5, "step_seconds", "got '\"1\"'"},
        {rows + "#end {\"step_seconds\": 1e999}\n", 5, "", "the #end line holds no JSON object"},
        {rows + "#end [1]\n", 5, "", "the #end line holds no JSON object: '[1]'"},
        {rows + "#end {\"a\": [[[[[1]]]]]}\n", 5, "", "nested deeper than 4 levels"},
        {rows + "#ending\n", 5, "", "expected '#end' or '#end {JSON object}', got '#ending'"},
        {rows + "#end\n0.09,0.5,0.9,0.5,0,0,0\n", 6, "", "nothing may follow the #end line"},
        {rows + "#end\n#end\n", 6, "", "nothing may follow the #end line"},
        {"t,x,y,z,vx,vy,vz\n0,0.5,0.9,0.5,0,0,0\n#end\n", 3, "", "an #end line after 1 rows; the scenario's clock takes 3"},
    };
    for (const auto& c : cases) {
        step_seconds(c.text, &problem);
        ASSERT_TRUE(problem) << c.text;
        EXPECT_EQ(problem->line, c.line) << c.text;
        EXPECT_EQ(problem->field, c.field) << c.text;
        EXPECT_NE(problem->reason.find(c.reason), std::string::npos) << problem->reason;
    }
}

// Binary rows (docs/external.md, Output): `#f64 N` then N rows of
// little-endian binary64. The golden file's rows as binary blocks, mixed with
// text rows, read the same as its text in any pieces; bytes that are newlines
// or '#' inside a block are values, not lines.
std::string binary_rows(const std::vector<State>& states, int dim, std::size_t from, std::size_t count) {
    std::string out = fmt::format("#f64 {}\n", count);
    for (std::size_t r = from; r < from + count; ++r) {
        std::vector<double> values{states[r].t};
        for (int i = 0; i < dim; ++i) values.push_back(states[r].p[i]);
        for (int i = 0; i < dim; ++i) values.push_back(states[r].v[i]);
        for (const double v : values) {
            const auto bits = std::bit_cast<std::uint64_t>(v);
            for (int b = 0; b < 8; ++b) out += static_cast<char>(bits >> (8 * b) & 0xff);
        }
    }
    return out;
}

TEST(TrajectoryReader, ReadsBinaryBlocksAsTheTextTheyStandFor) {
    const Scenario s = seed("seed-3d");
    const std::string text = slurp(kGolden3d);
    const std::vector<State> golden = read_all(s, text, text.size());
    ASSERT_GT(golden.size(), 300u);
    // Text row 0, a block of 1, a block of 200, text rows, a block of the rest.
    const std::size_t after_header = text.find('\n') + 1;
    std::string mixed = text.substr(0, text.find('\n', after_header) + 1);
    mixed += binary_rows(golden, 3, 1, 1) + binary_rows(golden, 3, 2, 200);
    std::size_t line_start = after_header;
    for (std::size_t r = 0; r < 202; ++r) line_start = text.find('\n', line_start) + 1;
    std::size_t line_end = line_start;
    for (std::size_t r = 202; r < 210; ++r) line_end = text.find('\n', line_end) + 1;
    mixed += text.substr(line_start, line_end - line_start);
    mixed += binary_rows(golden, 3, 210, golden.size() - 210) + "#end {\"step_seconds\": 0.5}\n";
    ASSERT_NE(mixed.find('\n', mixed.find("#f64 200")) , std::string::npos);
    for (std::size_t piece : {std::size_t{1}, std::size_t{5}, std::size_t{61}, mixed.size()}) {
        std::optional<RowProblem> problem;
        const std::vector<State> read = read_all(s, mixed, piece, &problem);
        ASSERT_FALSE(problem) << piece << ": " << problem->format();
        ASSERT_EQ(read.size(), golden.size()) << piece;
        for (std::size_t i = 0; i < golden.size(); ++i) {
            ASSERT_EQ(read[i].t, golden[i].t) << i;
            ASSERT_EQ(read[i].p, golden[i].p) << i;
            ASSERT_EQ(read[i].v, golden[i].v) << i;
        }
    }
}

TEST(TrajectoryReader, NamesWhatIsWrongWithABinaryBlock) {
    Scenario s = seed("seed-2d");
    s.duration = 2 * s.dt;  // three rows
    std::vector<State> states(3);
    for (int r = 0; r < 3; ++r) {
        states[static_cast<std::size_t>(r)].t = r * s.dt;
        states[static_cast<std::size_t>(r)].p = {0.5, 0.9, 0};
    }
    const std::string h = "t,x,y,vx,vy\n";
    std::vector<State> non_finite = states;
    non_finite[1].v[1] = std::numeric_limits<double>::quiet_NaN();
    std::vector<State> late = states;
    late[2].t = 3 * s.dt;
    const std::string whole = h + binary_rows(states, 2, 0, 3);
    const struct {
        std::string text;
        std::int64_t line;
        std::string field, reason;
    } cases[] = {
        {h + "#f64\n", 2, "", "expected '#f64 N' with N from 1 to 65536"},
        {h + "#f64 0\n", 2, "", "expected '#f64 N'"},
        {h + "#f64 65537\n", 2, "", "expected '#f64 N'"},
        {h + "#f64 2x\n", 2, "", "expected '#f64 N'"},
        {h + "#f64 4\n", 2, "", "a block of 4 binary rows after 0; the scenario's clock takes 3"},
        {whole.substr(0, whole.size() - 1), 5, "", "the stream ends inside a block of binary rows, 1 of them still to come"},
        {whole.substr(0, whole.size() - 40), 5, "", "the stream ends inside a block of binary rows, 1 of them"},
        {h + binary_rows(non_finite, 2, 0, 3), 4, "vy", "not finite: nan (a binary row)"},
        {h + binary_rows(late, 2, 0, 3), 5, "t", "is not row 2's time on the scenario's clock"},
        {whole + "0.09,0.5,0.9,0,0\n", 6, "", "more rows than the 3"},
    };
    for (const auto& c : cases) {
        for (std::size_t piece : {std::size_t{1}, std::size_t{7}, c.text.size()}) {
            std::optional<RowProblem> problem;
            read_all(s, c.text, piece, &problem);
            ASSERT_TRUE(problem) << c.reason;
            EXPECT_EQ(problem->line, c.line) << c.reason;
            EXPECT_EQ(problem->field, c.field) << c.reason;
            EXPECT_NE(problem->reason.find(c.reason), std::string::npos) << problem->reason;
        }
    }
    std::optional<RowProblem> problem;
    EXPECT_EQ(read_all(s, whole, 3, &problem).size(), 3u);
    EXPECT_FALSE(problem) << problem->format();
}

// ------------------------------------------------ declaring one in a scenario file

class ExternalDeclarations : public test::TestDirectory {
protected:
    std::string scenario_text(const std::string& more) const {
        return slurp(kScenarios + "/seed-3d.toml") + "\n" + more;
    }
    std::vector<Diagnostic> diagnostics(const std::string& more, const std::vector<std::string>& names = {}) {
        try {
            load_scenario(write_file("s.toml", scenario_text(more)), names);
        } catch (const ScenarioError& e) {
            return e.diagnostics();
        }
        return {};
    }
};

TEST_F(ExternalDeclarations, ReadsTheCommandAndPassesItsEngineTableOnAsWritten) {
    write_file("engine.sh", "#!/bin/sh\n");
    fs::permissions(dir_ / "engine.sh", fs::perms::owner_all);
    const Scenario s = load_scenario(write_file("s.toml", scenario_text(R"(
[external.mine]
command = ["./engine.sh", "--fast"]
[engines.mine]
solver = "pgs"
iterations = 20
nested = {restitution = 0.5, on = true}
[thresholds.mine]
trajectory_rms = 0.2
)")));
    ASSERT_EQ(s.externals.count("mine"), 1u);
    const auto& argv = s.externals.at("mine");
    ASSERT_EQ(argv.size(), 2u);
    EXPECT_EQ(fs::path(argv[0]), fs::absolute(dir_ / "engine.sh"));  // relative to the file's folder
    EXPECT_EQ(argv[1], "--fast");
    const auto table = nlohmann::json::parse(s.passthrough_tables.at("mine"));
    EXPECT_EQ(table["solver"], "pgs");
    EXPECT_EQ(table["iterations"], 20);
    EXPECT_EQ(table["nested"]["restitution"], 0.5);
    EXPECT_EQ(table["nested"]["on"], true);
    EXPECT_EQ(s.thresholds.for_simulator("mine").trajectory_rms, 0.2);

    // What the program reads: the scenario in SI units, with that table.
    const auto input = nlohmann::json::parse(external_input(s, "mine", "/tmp/settings"));
    EXPECT_EQ(input["protocol"], 1);
    EXPECT_EQ(input["dimension"], 3);
    EXPECT_EQ(input["position"].size(), 3u);
    EXPECT_EQ(input["gravity"][2].get<double>(), s.gravity.z());
    EXPECT_EQ(input["dt"].get<double>(), s.dt);
    EXPECT_EQ(input["steps"], document_step_count(s.dt, s.duration));
    EXPECT_EQ(input["engine"], table);
    EXPECT_EQ(input["settings_file"], "/tmp/settings");
    EXPECT_EQ(nlohmann::json::parse(external_input(s, "other", "x"))["engine"], nlohmann::json::object());
}

TEST_F(ExternalDeclarations, AcceptsTablesForExternalsDeclaredOnTheCommandLine) {
    EXPECT_TRUE(diagnostics("[engines.cli]\nk = 1\n[thresholds.cli]\ntrajectory_max = 1\n", {"cli"}).empty());
    const auto d = diagnostics("[engines.cli]\nk = 1\n");
    ASSERT_EQ(d.size(), 1u);
    EXPECT_EQ(d[0].key, "engines.cli");
    EXPECT_NE(d[0].reason.find("unknown engine"), std::string::npos);
}

TEST_F(ExternalDeclarations, RefusesBadDeclarationsWithTheirLines) {
    const struct {
        std::string toml, key, reason;
    } cases[] = {
        {"[external.ode]\ncommand = [\"sh\"]\n", "external.ode", "a built-in simulator's name"},
        {"[external.\".hidden\"]\ncommand = [\"sh\"]\n", "external.\".hidden\"", "must not start with '.'"},
        {"[external.mine]\ncommand = \"sh run.sh\"\n", "external.mine.command", "non-empty array of strings"},
        {"[external.mine]\ncommand = []\n", "external.mine.command", "non-empty array of strings"},
        {"[external.mine]\ncommand = [\"sh\", 1]\n", "external.mine.command", "non-empty array of strings"},
        {"[external.mine]\ncommand = [\"./missing\"]\n", "external.mine.command",
         "cannot run the program \"./missing\": it is not an executable file"},
        {"[external.mine]\ncommand = [\"no-such-program-anywhere\"]\n", "external.mine.command", "not found on PATH"},
        {"[external.mine]\ncommand = [\"\"]\n", "external.mine.command", "the program's name is empty"},
        {"[external.mine]\ncommand = [\"a\\nb\"]\n", "external.mine.command", "\"a\\u000Ab\": it is not found"},
        {"[external.mine]\nprogram = [\"sh\"]\n", "external.mine.command", "missing required key"},
        {"[external.mine]\ncommand = [\"sh\"]\nextra = 1\n", "external.mine.extra", "unknown key"},
    };
    for (const auto& c : cases) {
        const auto d = diagnostics(c.toml);
        ASSERT_FALSE(d.empty()) << c.toml;
        EXPECT_EQ(d[0].key, c.key) << c.toml;
        EXPECT_GT(d[0].line, 30) << c.toml;  // in the appended text, past the seed's own lines
        EXPECT_NE(d[0].reason.find(c.reason), std::string::npos) << d[0].reason;
    }
    const auto clash = diagnostics("[external.mine]\ncommand = [\"sh\"]\n", {"mine"});
    ASSERT_FALSE(clash.empty());
    EXPECT_NE(clash[0].reason.find("also declared by --external"), std::string::npos);
}

// ------------------------------------------------ running one

TEST(ExternalSimulator, ReplayingTheReferenceShowsNoDivergenceAndTheSettings) {
    const Scenario s = seed("seed-3d");
    const auto sim = replay("copy", "settings-ok");
    const ScenarioRun run = run_beside_reference(s, {sim.get()});
    const SimulatorSummary& r = run.results.at(1);
    ASSERT_EQ(r.status, RunStatus::ok) << r.reason;
    EXPECT_EQ(r.origin, "external: " + kReplay + " " + kGolden3d + " settings-ok");
    EXPECT_EQ(r.steps, run.results[0].steps);
    EXPECT_EQ(r.contacts, run.results[0].contacts);
    ASSERT_TRUE(run.comparisons[1]);
    EXPECT_EQ(run.comparisons[1]->vs_reference.trajectory.max, 0.0);
    EXPECT_NEAR(run.comparisons[1]->damping.normal_mean, s.alpha, 1e-9);
    ASSERT_EQ(r.settings.size(), 3u);
    EXPECT_EQ(r.settings[0].key, "protocol");
    EXPECT_EQ(r.settings[1].value, "replay 1");
    EXPECT_EQ(r.settings[2].value, "2");
}

// A program that times its own steps is charged for them: ns_per_step is
// its step time over the steps, and the rest of the run is reported apart.
// A step time over the whole run's is shown, not used.
TEST(ExternalSimulator, AReportedStepTimeIsTheCostPerStep) {
    const Scenario s = seed("seed-3d");
    const auto timed = replay("timed", "end"), slow = replay("slow", "end-slow"), early = replay("early", "end-early");
    const ScenarioRun run = run_beside_reference(s, {timed.get(), slow.get(), early.get()});
    const SimulatorSummary& r = run.results.at(1);
    ASSERT_EQ(r.status, RunStatus::ok) << r.reason;
    ASSERT_TRUE(r.step_seconds);
    EXPECT_EQ(*r.step_seconds, 1e-6);
    EXPECT_DOUBLE_EQ(r.ns_per_step(), 1e-6 * 1e9 / static_cast<double>(r.steps));
    EXPECT_GT(r.run_seconds, *r.step_seconds);
    EXPECT_EQ(run.comparisons[1]->vs_reference.trajectory.max, 0.0);  // the #end line changes no row

    const SimulatorSummary& lying = run.results.at(2);
    ASSERT_EQ(lying.status, RunStatus::ok) << lying.reason;
    EXPECT_FALSE(lying.step_seconds);
    EXPECT_DOUBLE_EQ(lying.ns_per_step(), lying.run_seconds * 1e9 / static_cast<double>(lying.steps));
    ASSERT_FALSE(lying.settings.empty());
    EXPECT_EQ(lying.settings.back().key, "step_seconds");
    EXPECT_EQ(lying.settings.back().value, "1000 s, ignored");

    EXPECT_EQ(run.results.at(3).status, RunStatus::failed);
    EXPECT_NE(run.results.at(3).reason.find("line 11: an #end line after 9 rows"), std::string::npos)
        << run.results.at(3).reason;
}

TEST(ExternalSimulator, RunsInTheScenarioFolderWithItsInput) {
    const Scenario s = seed("seed-3d");
    const fs::path copy = fs::temp_directory_path() / ("bouncecheck-input-" + std::to_string(::getpid()));
    const auto input = replay("in", "input", 600, copy.string());
    const auto pwd = replay("pwd", "pwd");
    const ScenarioRun run = run_beside_reference(s, {input.get(), pwd.get()});
    ASSERT_EQ(run.results[1].status, RunStatus::ok) << run.results[1].reason;
    const auto sent = nlohmann::json::parse(slurp(copy));
    fs::remove(copy);
    EXPECT_EQ(sent["scenario"], "seed-3d");
    EXPECT_EQ(sent["steps"], run.results[0].steps);
    EXPECT_FALSE(fs::exists(sent["settings_file"].get<std::string>()));  // removed after the run
    EXPECT_EQ(run.results[2].status, RunStatus::failed);
    EXPECT_NE(run.results[2].reason.find("exit status 4; stderr: " + fs::canonical(kScenarios).string()),
              std::string::npos)
        << run.results[2].reason;
}

TEST(ExternalSimulator, EachBrokenProgramCostsOnlyItsOwnRow) {
    const Scenario s = seed("seed-3d");
    const struct {
        const char* mode;
        std::string reason;
    } cases[] = {
        {"exit3", "exit status 3; stderr: engine exploded at step 9"},
        {"segv", "killed by signal 11"},
        {"badrow", "malformed trajectory: line 6: vx: not a number: 'abc'"},
        {"nan", "malformed trajectory: line 4: x: not finite: nan"},
        {"header", "malformed trajectory: line 1: expected the header"},
        {"few", "malformed trajectory: line 101: the trajectory ends after 99 rows; the scenario's clock takes 1401"},
        {"many", "malformed trajectory: line 1403: more rows than the 1401"},
        {"settings-bad", "its settings file: expected a JSON array"},
        {"hang", "no output for 0.5 s (--external-timeout): killed"},
    };
    std::vector<std::unique_ptr<const Simulator>> owned;
    std::vector<const Simulator*> sims;
    for (const auto& c : cases) {
        // Only the hanging program gets the short timeout: under a loaded
        // machine another could be slow to its first row and be killed for it.
        const double timeout = std::string(c.mode) == "hang" ? 0.5 : 60;
        owned.push_back(replay(c.mode, c.mode, timeout));
        sims.push_back(owned.back().get());
    }
    const auto good = replay("good", "ok");
    sims.push_back(good.get());
    const ScenarioRun run = run_beside_reference(s, sims);
    ASSERT_EQ(run.results.size(), std::size(cases) + 2);
    for (std::size_t i = 0; i < std::size(cases); ++i) {
        const SimulatorSummary& r = run.results[i + 1];
        EXPECT_EQ(r.simulator, cases[i].mode);
        EXPECT_EQ(r.status, RunStatus::failed) << cases[i].mode;
        EXPECT_NE(r.reason.find(cases[i].reason), std::string::npos) << cases[i].mode << ": " << r.reason;
    }
    const SimulatorSummary& last = run.results.back();
    EXPECT_EQ(last.status, RunStatus::ok) << last.reason;
    EXPECT_EQ(run.comparisons.back()->vs_reference.trajectory.max, 0.0);
    // Every program was reaped: this process has no child left, not even a zombie.
    EXPECT_EQ(::waitpid(-1, nullptr, WNOHANG), -1);
    EXPECT_EQ(errno, ECHILD);
}

// A grandchild the program leaves running dies with it when it times out.
TEST(ExternalSimulator, ATimeoutLeavesNoOrphan) {
    const Scenario s = seed("seed-3d");
    const fs::path pid_file = fs::temp_directory_path() / ("bouncecheck-orphan-" + std::to_string(::getpid()));
    const auto sim = replay("orphan", "orphan", 0.5, pid_file.string());
    const auto started = std::chrono::steady_clock::now();
    const SimulatorSummary r = record_run(*sim, s);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    EXPECT_EQ(r.status, RunStatus::failed);
    EXPECT_NE(r.reason.find("no output for 0.5 s"), std::string::npos) << r.reason;
    EXPECT_LT(seconds, 10) << "the program's sleep 60 was waited for";
    const pid_t grandchild = std::stoi(slurp(pid_file));
    fs::remove(pid_file);
    EXPECT_TRUE(dead(grandchild)) << "the program's child " << grandchild << " outlived its timeout";
}

// Ctrl-C reaches bouncecheck, not the program in its own process group: the
// interrupt handler kills that group before bouncecheck dies.
TEST(ExternalCli, AnInterruptKillsTheRunningProgram) {
    const fs::path pid_file = fs::temp_directory_path() / ("bouncecheck-interrupt-" + std::to_string(::getpid()));
    const fs::path out = fs::temp_directory_path() / ("bouncecheck-interrupt-out-" + std::to_string(::getpid()));
    fs::remove(pid_file);
    const std::string scenario = kScenarios + "/seed-3d.toml", out_dir = out.string();
    const std::string external = "hang=" + kReplay + " " + kGolden3d + " orphan " + pid_file.string();
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        ::execl(BOUNCECHECK_CLI, BOUNCECHECK_CLI, "run", scenario.c_str(), "--engines", "reference", "--external",
                external.c_str(), "--out", out_dir.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    std::string written;
    for (int i = 0; i < 500 && written.empty(); ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        written = slurp(pid_file);
    }
    ASSERT_FALSE(written.empty()) << "the program never started";
    const pid_t grandchild = std::stoi(written);
    ::kill(pid, SIGINT);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT);
    EXPECT_TRUE(dead(grandchild)) << "the program's child " << grandchild << " outlived the interrupt";
    fs::remove(pid_file);
    fs::remove_all(out);
}

TEST(ImportedTrajectory, TheReferencesOwnTrajectoryShowsZeroDivergence) {
    const Scenario s = seed("seed-3d");
    const auto copy = make_imported_trajectory("copy", kGolden3d);
    const ScenarioRun run = run_beside_reference(s, {copy.get()});
    const SimulatorSummary& r = run.results.at(1);
    ASSERT_EQ(r.status, RunStatus::ok) << r.reason;
    EXPECT_EQ(r.origin, "imported: " + kGolden3d);
    EXPECT_EQ(run.comparisons[1]->vs_reference.trajectory.rms, 0.0);
    EXPECT_EQ(run.comparisons[1]->vs_reference.trajectory.max, 0.0);
    EXPECT_EQ(r.apexes.size(), run.results[0].apexes.size());
}

// ------------------------------------------------ the examples

// The C++ example steps a built simulator behind the protocol: its rows are
// the built-in run's, bit for bit.
TEST(ExternalExamples, TheEngineWrapperMatchesTheBuiltInSimulatorBitForBit) {
    for (const char* scenario : {"seed-3d", "seed-2d"}) {
        Scenario s = seed(scenario);
        for (const auto& built : built_simulators()) {
            const std::string engine(built->name());
            if (engine != "reference" && engine != "ode" && engine != "box2d") continue;
            if (built->cannot_run(s)) continue;
            // The wrapper gets its own [engines.<name>-ext]: the built engine's settings, as a user would copy them.
            const EngineOptions o = s.engine_options(engine);
            nlohmann::json table = {{"tangential_model", o.tangential_model == TangentialModel::friction ? "friction"
                                                                                                          : "per-contact"},
                                    {"rotation", o.free_rotation ? "free" : "locked"},
                                    {"substeps", o.substeps}};
            if (o.tangential_model == TangentialModel::friction) table["friction"] = o.friction;
            if (o.ccd) table["ccd"] = *o.ccd;
            s.passthrough_tables[engine + "-ext"] = table.dump();
            const auto wrapped = make_external_simulator(
                ExternalDeclaration{engine + "-ext", {kEngineExample, engine}}, ExternalLimits{});
            const SimulatorSummary a = record_run(*built, s), b = record_run(*wrapped, s);
            ASSERT_EQ(b.status, RunStatus::ok) << scenario << " " << engine << ": " << b.reason;
            SCOPED_TRACE(std::string(scenario) + " " + engine);
            EXPECT_EQ(a.steps, b.steps) << engine;
            EXPECT_EQ(a.contacts, b.contacts) << engine;
            ASSERT_EQ(a.apexes.size(), b.apexes.size()) << engine;
            for (std::size_t i = 0; i < a.apexes.size(); ++i) EXPECT_EQ(a.apexes[i].height, b.apexes[i].height);
            EXPECT_EQ(a.final_state.p, b.final_state.p) << scenario << " " << engine;
            EXPECT_EQ(a.final_state.v, b.final_state.v) << scenario << " " << engine;
        }
    }
}

// The Python example, a semi-implicit Euler with the law's per-contact
// damping, through the command line: it measures the law's alpha and beta,
// and is nearer exact than the explicit reference (first order both, with a
// smaller constant).
TEST(ExternalExamples, ThePythonSimulatorRunsInRunSweepAndStress) {
    const fs::path out = fs::temp_directory_path() / ("bouncecheck-python-" + std::to_string(::getpid()));
    fs::remove_all(out);
    const std::string external = "--external 'semi=python3 " + kPythonExample + "'";
    CliResult r = bouncecheck("run " + kScenarios + "/seed-3d.toml " + kScenarios +
                              "/seed-2d.toml --engines reference --trajectories " + external + " --out " +
                              (out / "run").string());
    ASSERT_EQ(r.status, 1) << r.output;  // its divergence from the reference exceeds the seeds' thresholds
    const auto report = nlohmann::json::parse(slurp(out / "run" / "report.json"));
    for (const auto& sc : report["scenarios"]) {
        const auto& semi = sc["simulators"].back();
        ASSERT_EQ(semi["simulator"], "semi");
        EXPECT_EQ(semi["status"], "ok") << semi.dump();
        EXPECT_EQ(semi["origin"], "external: python3 " + kPythonExample);
        const auto& c = semi["comparison"];
        EXPECT_NEAR(c["damping"]["normal_mean"].get<double>(), 0.8, 1e-9) << semi.dump();
        EXPECT_NEAR(c["damping"]["tangential_mean"].get<double>(), 0.99, 1e-9) << semi.dump();
        EXPECT_LT(c["vs_exact"]["trajectory"]["rms"].get<double>(),
                  0.5 * sc["simulators"][0]["comparison"]["vs_exact"]["trajectory"]["rms"].get<double>());
        const std::string name = sc["scenario"]["name"];
        EXPECT_TRUE(fs::exists(out / "run" / name / "semi.csv"));
        // Its #end line: charged for its steps, its start-up reported apart.
        ASSERT_TRUE(semi["step_seconds"].is_number()) << semi.dump();
        EXPECT_GT(semi["outside_step_seconds"].get<double>(), 0.0);
        EXPECT_DOUBLE_EQ(semi["ns_per_step"].get<double>(),
                         semi["step_seconds"].get<double>() * 1e9 / semi["steps"].get<double>());
    }
    const std::string md = slurp(out / "run" / "report.md");
    EXPECT_NE(md.find("- semi: external: python3"), std::string::npos);
    EXPECT_NE(slurp(out / "run" / "junit.xml").find("seed-3d.semi"), std::string::npos);

    r = bouncecheck("sweep " + kScenarios + "/seed-3d.toml --engines reference --dt 0.03,0.015 --repeat 1 " +
                    external + " --out " + (out / "sweep").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const auto sweep = nlohmann::json::parse(slurp(out / "sweep" / "sweep.json"));
    int semi_rows = 0;
    for (const auto& row : sweep["rows"])
        if (row["engine"] == "semi") {
            ++semi_rows;
            EXPECT_EQ(row["status"], "ok") << row.dump();
            EXPECT_GT(row["outside_step_seconds"].get<double>(), 0.0) << row.dump();
        } else {
            EXPECT_TRUE(row["outside_step_seconds"].is_null()) << row.dump();  // built in: no start-up to set apart
        }
    EXPECT_EQ(semi_rows, 2);

    r = bouncecheck("stress --engines reference --only zero-gravity --only fast-5 " + external + " --out " +
                    (out / "stress").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const auto stress = nlohmann::json::parse(slurp(out / "stress" / "stress.json"));
    int semi_runs = 0;
    for (const auto& result : stress["results"])
        if (result["simulator"] == "semi") {
            ++semi_runs;
            EXPECT_EQ(result["outcome"], "pass") << result.dump();
        }
    EXPECT_EQ(semi_runs, 2);
    fs::remove_all(out);
}

// ------------------------------------------------ the command line

TEST(ExternalCli, BadDeclarationsAreBadInput) {
    const std::string seed3d = kScenarios + "/seed-3d.toml", seed2d = kScenarios + "/seed-2d.toml";
    const struct {
        std::string args, message;
    } cases[] = {
        {"run " + seed3d + " --external mine", "--external mine: expected NAME=COMMAND"},
        {"run " + seed3d + " --external 'mine= '", "the command is empty"},
        {"run " + seed3d + " --external 'exact=sh'", "'exact' is a built-in simulator's name"},
        {"run " + seed3d + " --external 'a b=sh'", "is not usable as a folder name"},
        {"run " + seed3d + " --external m=sh --external m=sh", "'m' is declared twice"},
        {"run " + seed3d + " --external m=./no-such-engine", "is not an executable file"},
        {"sweep " + seed3d + " --external m=no-such-engine-on-path", "is not found on PATH"},
        {"stress --external m=no-such-engine-on-path", "is not found on PATH"},
        {"run " + seed3d + " --trajectory copy", "expected NAME=FILE.csv"},
        {"run " + seed3d + " " + seed2d + " --trajectory copy=" + kGolden3d, "say which one"},
        {"run " + seed3d + " --trajectory copy@nope=" + kGolden3d, "no scenario named 'nope'"},
        {"run " + seed3d + " --trajectory ode=" + kGolden3d, "a built-in simulator's name"},
        {"run " + seed2d + " --trajectory copy=" + kGolden3d, "seed-3d.csv:1: expected the header 't,x,y,vx,vy'"},
        {"run " + seed3d + " --trajectory copy=/no/such.csv", "/no/such.csv: cannot open"},
        {"run " + seed3d + " --external m=sh --trajectory m=" + kGolden3d, "'m' already names a simulator"},
    };
    for (const auto& c : cases) {
        const CliResult r = bouncecheck(c.args);
        EXPECT_EQ(r.status, 2) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << "\n" << r.output;
    }
}

// The hostile audit's finding 12: a pipe given as a recorded trajectory passed
// the check (the first read) and was then empty in the run (exit 3).
TEST(ExternalCli, ARecordedTrajectoryMustBeAFileNotAPipe) {
    const fs::path fifo = fs::temp_directory_path() / ("bouncecheck-trajectory-fifo-" + std::to_string(::getpid()));
    fs::remove(fifo);
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const CliResult r = bouncecheck("run " + kScenarios + "/seed-3d.toml --engines reference --trajectory copy=" +
                                    fifo.string() + " --out " + (fifo.string() + "-out"));
    fs::remove(fifo);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(fifo.string() + ": not a regular file: a recorded trajectory is read twice"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(fifo.string() + "-out/report.json"));
    fs::remove_all(fifo.string() + "-out");
}

TEST(ExternalCli, AFailedExternalExitsThreeWithEveryOtherResultWritten) {
    const fs::path out = fs::temp_directory_path() / ("bouncecheck-ext-cli-" + std::to_string(::getpid()));
    fs::remove_all(out);
    const CliResult r = bouncecheck("run " + kScenarios + "/seed-3d.toml --engines reference --trajectories " +
                                    "--external 'good=" + kReplay + " " + kGolden3d + " ok' --external 'bad=" +
                                    kReplay + " " + kGolden3d + " segv' --trajectory copy=" + kGolden3d +
                                    " --out " + out.string());
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_NE(r.output.find("good (external: "), std::string::npos) << r.output;
    const auto report = nlohmann::json::parse(slurp(out / "report.json"));
    const auto& sims = report["scenarios"][0]["simulators"];
    std::map<std::string, std::string> status;
    for (const auto& sim : sims) status[sim["simulator"]] = sim["status"];
    EXPECT_EQ(status["good"], "ok");
    EXPECT_EQ(status["bad"], "failed");
    EXPECT_EQ(status["copy"], "ok");
    // The trajectory files of both good rows are the reference's, byte for byte.
    EXPECT_EQ(slurp(out / "seed-3d" / "good.csv"), slurp(kGolden3d));
    EXPECT_EQ(slurp(out / "seed-3d" / "copy.csv"), slurp(kGolden3d));
    fs::remove_all(out);
}

}  // namespace
}  // namespace bouncecheck
