// The `bouncecheck` command end to end, as a user or a CI script runs it.
#include "tests/support/cli.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

using bouncecheck::test::CliResult;
using bouncecheck::test::bouncecheck;
using bouncecheck::test::slurp;

fs::path fresh_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("bouncecheck-test-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    return dir;
}

const std::string kData = BOUNCECHECK_TEST_DATA;
const std::string kScenarios = BOUNCECHECK_SCENARIO_DIR;

TEST(Cli, RunBundledWritesGoldenTrajectoriesAndReport) {
    const fs::path out = fresh_dir("run");
    const CliResult r = bouncecheck("run --trajectories --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("seed-2d"), std::string::npos);
    EXPECT_NE(r.output.find("seed-3d"), std::string::npos);
    // The reference's trajectory files are the golden files, byte for byte.
    EXPECT_EQ(slurp(out / "seed-2d" / "reference.csv"), slurp(kData + "/seed-2d.csv"));
    EXPECT_EQ(slurp(out / "seed-3d" / "reference.csv"), slurp(kData + "/seed-3d.csv"));
    // exact is sampled at the reference's times: same rows, same t column.
    for (const char* name : {"seed-2d", "seed-3d"}) {
        std::ifstream ref(out / name / "reference.csv"), ex(out / name / "exact.csv");
        std::string a, b;
        int rows = 0;
        while (std::getline(ref, a)) {
            ASSERT_TRUE(std::getline(ex, b)) << name << " exact.csv is short at row " << rows;
            EXPECT_EQ(a.substr(0, a.find(',')), b.substr(0, b.find(','))) << name << " row " << rows;
            ++rows;
        }
        EXPECT_FALSE(std::getline(ex, b)) << name << " exact.csv has extra rows";
    }
    const auto report = nlohmann::json::parse(slurp(out / "report.json"));
    EXPECT_EQ(report["schema"], "bouncecheck-report/1");
    EXPECT_NE(slurp(out / "report.html").find("\"kind\":\"run\""), std::string::npos);
    // seed-2d, seed-3d, their per-contact variants, earth-drop and game-throw
    ASSERT_EQ(report["scenarios"].size(), 6u);
    for (const auto& sc : report["scenarios"]) {
        ASSERT_GE(sc["simulators"].size(), 2u);
        EXPECT_EQ(sc["simulators"][0]["simulator"], "reference");
        EXPECT_EQ(sc["simulators"][1]["simulator"], "exact");
        for (const auto& sim : sc["simulators"]) {
            // A simulator that cannot run a scenario (box2d on 3D) is skipped, with its reason.
            if (sim["status"] == "skipped") {
                EXPECT_FALSE(sim["reason"].get<std::string>().empty()) << sim.dump();
            } else {
                EXPECT_EQ(sim["status"], "ok") << sim.dump();
            }
        }
    }
    for (const auto& sc : report["scenarios"]) {
        if (sc["scenario"]["name"] == "seed-3d") {
            EXPECT_EQ(sc["simulators"][0]["steps"], 1400);
            // exact's first floor contact: at 5.6556 s, restitution alpha at the instant.
            const auto& first = sc["simulators"][1]["first_floor_contacts"][0];
            EXPECT_NEAR(first["t"].get<double>(), 5.6556, 1e-4);
            EXPECT_NEAR(first["restitution"].get<double>(), 0.8, 1e-12);
            // exact is still from just after its Zeno time (34.03 s): the
            // remaining samples are filled, and the report says from when.
            const auto& exact = sc["simulators"][1];
            ASSERT_TRUE(exact["filled_from"].is_number()) << exact.dump();
            EXPECT_NEAR(exact["filled_from"].get<double>(), 34.08, 1e-9);
            EXPECT_EQ(exact["fill_period_steps"], 1);
            EXPECT_EQ(exact["fill_steps"], 1400 - 1136 + 1);  // samples 1136 (t = 34.08) to 1400
            // The reference repeats only after about 1.1e6 steps.
            EXPECT_TRUE(sc["simulators"][0]["filled_from"].is_null());
            EXPECT_EQ(sc["simulators"][0]["fill_steps"], 0);
        }
    }
    // No temporary file is left beside the outputs.
    for (const auto& e : fs::recursive_directory_iterator(out))
        EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << e.path();
    fs::remove_all(out);
}

TEST(Cli, EnginesSelectsSimulatorsAndRejectsUnknownOnes) {
    const fs::path out = fresh_dir("engines");
    CliResult r = bouncecheck("run " + kScenarios + "/seed-3d.toml --engines exact --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.output;
    const auto report = nlohmann::json::parse(slurp(out / "report.json"));
    ASSERT_EQ(report["scenarios"][0]["simulators"].size(), 1u);
    EXPECT_EQ(report["scenarios"][0]["simulators"][0]["simulator"], "exact");
    r = bouncecheck("run --engines reference,warp-drive --out " + out.string());
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("warp-drive"), std::string::npos) << r.output;
    fs::remove_all(out);
}

// The run's last line says its exit status and why, in words, for each status.
TEST(Cli, RunEndsWithItsVerdictAndExitStatus) {
    const fs::path out = fresh_dir("verdict");
    const std::string seed = kScenarios + "/seed-2d.toml --out " + out.string();
    const auto last_line = [](const std::string& output) {
        std::string text = output;
        while (!text.empty() && text.back() == '\n') text.pop_back();
        const auto at = text.rfind("\nverdict: ");
        return at == std::string::npos ? std::string() : text.substr(at + 1);
    };
    CliResult r = bouncecheck("run " + seed + " --engines reference,exact");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(last_line(r.output), "verdict: every simulator ran and every threshold held (exit 0)") << r.output;
    // The terminal's block order: summary, comparison, then the ranking (none: no engine ran).
    EXPECT_LT(r.output.find("first apex heights"), r.output.find("apex err")) << r.output;
    EXPECT_EQ(r.output.find("closest to"), std::string::npos) << r.output;

    r = bouncecheck("run " + seed + " --engines reference,exact --threshold error_bounce_height_rel=0.01");
    ASSERT_EQ(r.status, 1) << r.output;
    EXPECT_EQ(last_line(r.output), "verdict: one run exceeded a threshold (reference on seed-2d) (exit 1)") << r.output;
    EXPECT_NE(slurp(out / "report.md").find("**verdict: one run exceeded a threshold (reference on seed-2d) (exit 1)**"),
              std::string::npos);

    r = bouncecheck("run " + seed + " --engines exact --external broken=/bin/false");
    ASSERT_EQ(r.status, 3) << r.output;
    EXPECT_EQ(last_line(r.output),
              "verdict: 1 simulator run failed (broken on seed-2d); the other results are written (exit 3)")
        << r.output;
    // Its rows show only the failure: no figure, no verdict beside it.
    EXPECT_NE(r.output.find("\n  broken    FAILED\n"), std::string::npos) << r.output;
    fs::remove_all(out);
}

TEST(Cli, InvalidScenarioExits2WithLocatedMessageAndRunsNothing) {
    const fs::path out = fresh_dir("invalid");
    fs::create_directories(out);
    const fs::path bad = out / "bad.toml";
    std::string text = slurp(kScenarios + "/seed-3d.toml");
    text.replace(text.find("radius = 0.05"), 13, "radius = -0.05");
    std::ofstream(bad) << text;
    const CliResult r = bouncecheck("run " + bad.string() + " --out " + (out / "o").string());
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find(bad.string() + ":"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("ball.radius"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out / "o" / "report.json"));
    fs::remove_all(out);
}

TEST(Cli, ValidateReportsEachFile) {
    CliResult r = bouncecheck("validate " + kScenarios + "/seed-2d.toml " + kScenarios + "/seed-3d.toml");
    EXPECT_EQ(r.status, 0) << r.output;
    r = bouncecheck("validate " + kScenarios + "/seed-2d.toml /nonexistent/missing.toml");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("missing.toml"), std::string::npos) << r.output;
}

TEST(Cli, UsageErrorsExit2AndHelpExits0) {
    EXPECT_EQ(bouncecheck("").status, 2);
    EXPECT_EQ(bouncecheck("frobnicate").status, 2);
    EXPECT_EQ(bouncecheck("run --no-such-flag").status, 2);
    // The watchdog needs the engine in a child process to kill.
    const CliResult budget = bouncecheck("run --budget 5 --in-process");
    EXPECT_EQ(budget.status, 2);
    EXPECT_NE(budget.output.find("--in-process"), std::string::npos) << budget.output;
    EXPECT_EQ(bouncecheck("run --budget 0").status, 2);
    EXPECT_EQ(bouncecheck("sweep " + kScenarios + "/seed-2d.toml --budget -1").status, 2);
    for (const char* cmd : {"--help", "run --help", "validate --help", "list --help"}) {
        const CliResult r = bouncecheck(cmd);
        EXPECT_EQ(r.status, 0) << cmd;
        EXPECT_NE(r.output.find("Usage"), std::string::npos) << cmd << r.output;
    }
}

TEST(Cli, ListShowsBundledScenariosAndSimulators) {
    const CliResult r = bouncecheck("list");
    ASSERT_EQ(r.status, 0);
    for (const char* name : {"seed-2d", "seed-3d", "reference", "exact"})
        EXPECT_NE(r.output.find(name), std::string::npos) << name;
}

}  // namespace

namespace {

// Ctrl-C in the middle of writing trajectories: the process dies of SIGINT,
// leaves no temporary file, and every output file present is complete.
TEST(Cli, InterruptLeavesNoHalfWrittenFile) {
    const fs::path out = fresh_dir("interrupt");
    fs::create_directories(out);
    // Long enough (1e6 steps) that the run is still writing when interrupted.
    std::string scenario = slurp(kScenarios + "/seed-2d.toml");
    scenario.replace(scenario.find("duration = 50.0"), 15, "duration = 30000.0");
    std::ofstream(out / "long.toml") << scenario;

    const std::string out_dir = (out / "o").string(), file = (out / "long.toml").string();
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        ::execl(BOUNCECHECK_CLI, BOUNCECHECK_CLI, "run", file.c_str(), "--engines", "reference,exact",
                "--trajectories", "--out", out_dir.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    // Interrupt once the first trajectory file is being written.
    for (int i = 0; i < 400; ++i) {
        bool writing = false;
        std::error_code ec;
        for (const auto& e : fs::recursive_directory_iterator(out / "o", ec))
            writing = writing || e.path().string().find(".tmp.") != std::string::npos;
        if (writing) break;
        ::usleep(10'000);
    }
    ::kill(pid, SIGINT);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the run finished before the interrupt: make it longer";
    EXPECT_EQ(WTERMSIG(status), SIGINT);

    for (const auto& e : fs::recursive_directory_iterator(out / "o")) {
        EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << "left behind: " << e.path();
        if (e.path().extension() == ".csv") {
            // A complete trajectory: 1,000,001 rows after the header, the last one whole.
            std::ifstream in(e.path());
            std::string line, last;
            std::size_t rows = 0;
            while (std::getline(in, line)) ++rows, last = line;
            EXPECT_EQ(rows, 1'000'002u) << e.path();
        }
    }
    fs::remove_all(out);
}

}  // namespace

namespace {

// FNV-1a of every file under `dir`, by relative path.
std::map<std::string, std::uint64_t> digests(const fs::path& dir) {
    std::map<std::string, std::uint64_t> out;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        if (!e.is_regular_file()) continue;
        std::uint64_t h = 1469598103934665603ull;
        for (unsigned char c : slurp(e.path())) h = (h ^ c) * 1099511628211ull;
        out[fs::relative(e.path(), dir).string()] = h;
    }
    return out;
}

// Determinism: the same input gives the same bytes in every output file
// (reports, page, trajectories) on every run, once wall-clock times are left out.
TEST(Cli, SameInputSameOutputBits) {
    const fs::path a = fresh_dir("det-a"), b = fresh_dir("det-b");
    for (const fs::path& dir : {a, b}) {
        const CliResult r = bouncecheck("run --no-timings --trajectories --out " + dir.string());
        ASSERT_EQ(r.status, 0) << r.output;
    }
    const auto da = digests(a), db = digests(b);
    const auto report = nlohmann::json::parse(slurp(a / "report.json"));
    // Five reports, the folder's manifest (which holds digests, no time), and a
    // trajectory per scenario and simulator that ran (whichever engines this build has).
    std::size_t ran = 0;
    for (const auto& scenario : report["scenarios"])
        for (const auto& sim : scenario["simulators"]) ran += sim["status"] != "skipped";
    EXPECT_GE(ran, 6u * 2);  // reference and exact at least, on the six bundled scenarios
    EXPECT_EQ(da.size(), 6 + ran);
    EXPECT_EQ(da, db);
    // And no wall-clock figure slipped in (a skipped simulator has none at all).
    for (const auto& scenario : report["scenarios"])
        for (const auto& sim : scenario["simulators"])
            if (sim["status"] != "skipped") EXPECT_TRUE(sim.at("run_seconds").is_null()) << sim["simulator"];
    fs::remove_all(a);
    fs::remove_all(b);
}

}  // namespace
