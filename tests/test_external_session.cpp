// Session programs (docs/external.md, Sessions): one process answers
// scenario after scenario, kept by the harness while its replies are whole
// and ended at the first that is not, without costing another row.
#include "commands/run/run_pipeline.h"
#include "external/external_simulator.h"
#include "metrics/summary.h"
#include "reference/reference_simulator.h"
#include "scenarios/loader.h"
#include "tests/support/cli.h"
#include "tests/support/engine_run.h"
#include "tests/support/engine_tests.h"
#include "tests/support/processes.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;

namespace bouncecheck {
namespace {

using test::bouncecheck;
using test::CliResult;
using test::dead;

const std::string kData = BOUNCECHECK_TEST_DATA;
const std::string kScenarios = BOUNCECHECK_SCENARIO_DIR;
const std::string kSession = kData + "/external/session.sh";
const std::string kGolden3d = kData + "/seed-3d.csv";  // the reference's seed-3d trajectory
const std::string kPythonExample = BOUNCECHECK_EXAMPLES "/semi_implicit_euler.py";

Scenario seed(const char* name) { return load_scenario(kScenarios + "/" + name + ".toml"); }

std::unique_ptr<const Simulator> session_program(const std::string& name, std::vector<std::string> argv,
                                                 double silence_seconds = 600) {
    ExternalDeclaration d(name, std::move(argv));
    d.session = true;
    return make_external_simulator(std::move(d), ExternalLimits{silence_seconds});
}

std::unique_ptr<const Simulator> replaying(const std::string& mode, const std::string& pids = "",
                                           double silence_seconds = 600) {
    std::vector<std::string> argv{kSession, kGolden3d, mode};
    if (!pids.empty()) argv.push_back(pids);
    return session_program("replay", std::move(argv), silence_seconds);
}

std::vector<std::string> lines_of(const fs::path& file) {
    std::ifstream in(file);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

fs::path pid_file(const char* what) {
    const fs::path file = fs::temp_directory_path() / fmt::format("bouncecheck-session-{}-{}", what, ::getpid());
    fs::remove(file);
    return file;
}

// The same program answers every scenario, each reply exactly the one-shot
// program's: a session changes the cost, not the result.
TEST(ExternalSession, OneProcessAnswersScenarioAfterScenario) {
    const fs::path pids = pid_file("reuse");
    const auto sim = replaying("ok", pids.string());
    const Scenario s = seed("seed-3d");
    const auto reference = make_reference_simulator();
    const SimulatorSummary expected = record_run(*reference, s);
    for (int run = 0; run < 3; ++run) {
        const SimulatorSummary r = record_run(*sim, s);
        ASSERT_EQ(r.status, RunStatus::ok) << r.reason;
        EXPECT_EQ(r.steps, expected.steps);
        EXPECT_EQ(r.final_state.p, expected.final_state.p);
        ASSERT_TRUE(r.step_seconds);
        EXPECT_EQ(*r.step_seconds, 1e-6);
    }
    const auto answered = lines_of(pids);
    ASSERT_EQ(answered.size(), 3u);
    EXPECT_EQ(std::set<std::string>(answered.begin(), answered.end()).size(), 1u) << "one process for all three";
    fs::remove(pids);
}

// A session whose program exited after a whole reply is replaced, not
// blamed: the next scenario goes to a new process.
TEST(ExternalSession, AProgramThatLeftIsReplacedForTheNextScenario) {
    const fs::path pids = pid_file("once");
    const auto sim = replaying("once", pids.string());
    const Scenario s = seed("seed-3d");
    for (int run = 0; run < 3; ++run) {
        const SimulatorSummary r = record_run(*sim, s);
        ASSERT_EQ(r.status, RunStatus::ok) << "run " << run << ": " << r.reason;
    }
    const auto answered = lines_of(pids);
    EXPECT_EQ(std::set<std::string>(answered.begin(), answered.end()).size(), answered.size());
    fs::remove(pids);
}

// A reply without its #end line fails its own row, naming the cause, and
// ends the session: the next scenario starts a new process; nothing is
// left running.
TEST(ExternalSession, AReplyWithoutItsEndLineFailsOnlyItsRow) {
    const fs::path pids = pid_file("no-end");
    const auto sim = replaying("no-end", pids.string(), /*silence_seconds=*/1);
    const Scenario s = seed("seed-3d");
    for (int run = 0; run < 2; ++run) {
        const SimulatorSummary r = record_run(*sim, s);
        EXPECT_EQ(r.status, RunStatus::failed);
        EXPECT_NE(r.reason.find("no #end line after them"), std::string::npos) << r.reason;
        EXPECT_NE(r.reason.find("no output for 1 s"), std::string::npos) << r.reason;
    }
    const auto answered = lines_of(pids);
    ASSERT_EQ(answered.size(), 2u);
    EXPECT_NE(answered[0], answered[1]);
    for (const std::string& pid : answered) EXPECT_TRUE(dead(std::stoi(pid))) << pid;
    fs::remove(pids);
}

// A session that hangs in its second reply is stopped at the limit, with
// everything it started; the first scenario's result stands.
TEST(ExternalSession, AHangInALaterReplyCostsOnlyThatRow) {
    const fs::path pids = pid_file("hang");
    const auto sim = replaying("second-hangs", pids.string(), /*silence_seconds=*/1);
    const Scenario s = seed("seed-3d");
    const SimulatorSummary first = record_run(*sim, s);
    EXPECT_EQ(first.status, RunStatus::ok) << first.reason;
    const SimulatorSummary second = record_run(*sim, s);
    EXPECT_EQ(second.status, RunStatus::failed);
    const auto answered = lines_of(pids);
    ASSERT_EQ(answered.size(), 2u);
    EXPECT_EQ(answered[0], answered[1]) << "the second scenario went to the first one's process";
    EXPECT_TRUE(dead(std::stoi(answered[0])));
    fs::remove(pids);
}

// The Python example's --session mode through the command line: the stress
// suite's runs share one Python process per worker, with the one-shot
// program's results.
TEST(ExternalSession, ThePythonExampleAnswersTheStressSuiteInSessions) {
    const fs::path dir = fs::temp_directory_path() / fmt::format("bouncecheck-session-stress-{}", ::getpid());
    fs::remove_all(dir);
    const std::string common = "stress --engines exact --only monte-carlo --monte-carlo 12 --jobs 2 ";
    const CliResult session = bouncecheck(common + "--external-session 'py=python3 " + kPythonExample +
                                          " --session' --out " + (dir / "session").string());
    const CliResult one_shot =
        bouncecheck(common + "--external 'py=python3 " + kPythonExample + "' --out " + (dir / "one-shot").string());
    ASSERT_EQ(session.status, 0) << session.output;
    ASSERT_EQ(one_shot.status, 0) << one_shot.output;
    const auto results = [&](const char* which) {
        std::ifstream in(dir / which / "stress.json");
        std::map<std::string, std::string> outcome;
        const nlohmann::json report = nlohmann::json::parse(in);
        for (const auto& r : report["results"])
            if (r["simulator"] == "py") outcome[r["scenario"]] = r["outcome"].get<std::string>() + " " + r["steps"].dump();
        return outcome;
    };
    const auto with_sessions = results("session");
    EXPECT_EQ(with_sessions.size(), 12u);
    EXPECT_EQ(with_sessions, results("one-shot"));
    fs::remove_all(dir);
}

}  // namespace
}  // namespace bouncecheck
