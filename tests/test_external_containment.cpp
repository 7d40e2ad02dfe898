// An external program is contained in time and in processes, and a run it
// is part of leaves nothing behind (the hostile audit's findings 8, 14 and
// 17): one overall limit besides the silence limit; every process it
// starts, even one that left its process group or session, gone when it
// ends; no settings file left in the temporary folder after an interrupt or
// a watchdog's kill; no half-written output after a failed rename.
#include "tests/support/cli.h"
#include "tests/support/processes.h"
#include "tests/support/test_directory.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace bouncecheck {
namespace {

using test::bouncecheck;
using test::CliResult;
using test::dead;
using test::slurp;

const std::string kScenarios = BOUNCECHECK_SCENARIO_DIR;
const std::string kPythonExample = BOUNCECHECK_EXAMPLES "/semi_implicit_euler.py";

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The reason report.json gives for simulator `name`'s row of the first scenario.
std::string row_reason(const fs::path& out, const std::string& name, std::string* status = nullptr) {
    const nlohmann::json report = nlohmann::json::parse(slurp(out / "report.json"));
    for (const auto& sim : report["scenarios"][0]["simulators"]) {
        if (sim["simulator"] != name) continue;
        if (status) *status = sim.at("status").get<std::string>();
        return sim.value("reason", std::string());
    }
    return "no row";
}

// Starts the built binary with `args` and TMPDIR set to `tmp`, not waiting.
pid_t start_bouncecheck(const std::vector<std::string>& args, const fs::path& tmp) {
    const pid_t pid = ::fork();
    if (pid != 0) return pid;
    ::setenv("TMPDIR", tmp.c_str(), 1);
    std::vector<char*> argv{const_cast<char*>(BOUNCECHECK_CLI)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const int devnull = ::open("/dev/null", O_WRONLY);
    ::dup2(devnull, STDOUT_FILENO);
    ::dup2(devnull, STDERR_FILENO);
    ::execv(BOUNCECHECK_CLI, argv.data());
    ::_exit(127);
}

// The names in `dir` that start with `prefix`.
std::vector<std::string> entries_starting(const fs::path& dir, const std::string& prefix) {
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(dir))
        if (entry.path().filename().string().rfind(prefix, 0) == 0) found.push_back(entry.path().filename());
    return found;
}

class ExternalContainment : public test::TestDirectory {};

// Finding 17: processes that left the program's process group (setpgid),
// its session (setsid), or were orphaned on purpose (a double fork) die
// with the program; and one that keeps standard output open does not make
// the row wait for the silence limit.
TEST_F(ExternalContainment, EscapedDescendantsDieWithTheProgramAndDoNotHoldTheRow) {
    const fs::path pids = dir_ / "pids";
    fs::create_directories(pids);
    const fs::path program = write_file("escape.py", R"(import os, subprocess, sys, time
data = sys.stdin.read()
def escape(how, keep_stdout):
    if os.fork() > 0:
        return
    if how == 'setsid':
        os.setsid()
    elif how == 'setpgid':
        os.setpgid(0, 0)
    elif how == 'double':
        if os.fork() > 0:
            os._exit(0)
        os.setsid()
    if not keep_stdout:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 1)
        os.dup2(null, 2)
    open(os.path.join(sys.argv[1], how + '-' + str(os.getpid())), 'w').close()
    time.sleep(600)
    os._exit(0)
escape('setsid', True)  # holds the row's standard output open
escape('setpgid', False)
escape('double', False)
while len(os.listdir(sys.argv[1])) < 3:
    time.sleep(0.01)
subprocess.run([sys.executable, sys.argv[2]], input=data.encode(), check=True)
)");
    const fs::path out = dir_ / "out";
    const auto started = std::chrono::steady_clock::now();
    const CliResult r = bouncecheck("run " + kScenarios + "/seed-2d.toml --engines reference --external 'esc=python3 " +
                                    program.string() + " " + pids.string() + " " + kPythonExample +
                                    "' --external-timeout 30 --out " + out.string());
    const double seconds = seconds_since(started);
    std::string status;
    EXPECT_EQ(row_reason(out, "esc", &status), "") << r.output;
    EXPECT_EQ(status, "ok") << r.output;
    EXPECT_LT(seconds, 20) << "the row waited for a descendant holding its standard output";
    std::vector<std::string> escaped;
    for (const auto& entry : fs::directory_iterator(pids)) escaped.push_back(entry.path().filename());
    ASSERT_EQ(escaped.size(), 3u);
    for (const std::string& name : escaped) {
        const pid_t pid = std::stoi(name.substr(name.find('-') + 1));
        EXPECT_TRUE(dead(pid)) << name << " outlived the run";
    }
}

// Finding 8: a program that keeps writing, a byte at a time, never trips
// the silence limit; the command's --budget stops it all the same.
TEST_F(ExternalContainment, ATricklingProgramIsStoppedAtTheBudget) {
    const fs::path program = write_file("trickle.sh", "cat > /dev/null\nwhile :; do printf 0; sleep 0.2; done\n");
    const fs::path out = dir_ / "out";
    const auto started = std::chrono::steady_clock::now();
    const CliResult r = bouncecheck("run " + kScenarios + "/seed-2d.toml --engines reference --external 'slow=/bin/sh " +
                                    program.string() + "' --external-timeout 3 --budget 2 --out " + out.string());
    const double seconds = seconds_since(started);
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_LT(seconds, 15);
    EXPECT_NE(row_reason(out, "slow").find("still running after 2 s, its limit in all: killed"), std::string::npos)
        << r.output;
}

// Finding 14: SIGINT or SIGTERM while an external runs leaves no settings
// file in the temporary folder (and kills the program, as before).
TEST_F(ExternalContainment, AnInterruptLeavesNoSettingsFile) {
    for (const int sig : {SIGINT, SIGTERM}) {
        const fs::path tmp = dir_ / ("tmp-" + std::to_string(sig)), marker = dir_ / ("started-" + std::to_string(sig));
        fs::create_directories(tmp);
        const fs::path program = write_file("hang.sh", "cat > /dev/null\ntouch \"$1\"\nsleep 60\n");
        const pid_t pid = start_bouncecheck({"run", kScenarios + "/seed-2d.toml", "--engines", "reference", "--external",
                                             "hang=/bin/sh " + program.string() + " " + marker.string(), "--out",
                                             (dir_ / "out").string()},
                                            tmp);
        ASSERT_GT(pid, 0);
        for (int i = 0; i < 1000 && !fs::exists(marker); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
        ASSERT_TRUE(fs::exists(marker)) << "the program never started";
        EXPECT_EQ(entries_starting(tmp, "bouncecheck-settings-").size(), 1u) << "the settings file is made in TMPDIR";
        ::kill(pid, sig);
        int status = 0;
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
        EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig);
        EXPECT_EQ(entries_starting(tmp, "bouncecheck-settings-"), std::vector<std::string>{}) << "signal " << sig;
    }
}

// Finding 14: a stress run stops a hanging external in a worker process
// (at its budget now, where the audit saw the watchdog kill the worker);
// its settings file goes with it.
TEST_F(ExternalContainment, AStoppedStressRunLeavesNoSettingsFile) {
    const fs::path tmp = dir_ / "tmp";
    fs::create_directories(tmp);
    const fs::path program = write_file("hang.sh", "cat > /dev/null\nsleep 60\n");
    const pid_t pid = start_bouncecheck({"stress", "--only", "zero-gravity", "--engines", "reference", "--external",
                                         "hang=/bin/sh " + program.string(), "--budget", "1", "--out",
                                         (dir_ / "out").string()},
                                        tmp);
    ASSERT_GT(pid, 0);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 3) << status;
    EXPECT_EQ(entries_starting(tmp, "bouncecheck-settings-"), std::vector<std::string>{});
}

// Finding 14: an output that cannot be renamed into place (a folder holds
// its name) is a clear error naming it, leaves no temporary file, and costs
// only itself: every other report is still written.
TEST_F(ExternalContainment, AFailedRenameNamesTheFileAndLeavesNoTemporary) {
    const fs::path out = dir_ / "out";
    fs::create_directories(out / "report.json" / "inside");
    const CliResult r = bouncecheck("run " + kScenarios + "/seed-2d.toml --engines reference --out " + out.string());
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_NE(r.output.find("cannot write " + (out / "report.json").string() + ": Is a directory"), std::string::npos)
        << r.output;
    for (const auto& entry : fs::directory_iterator(out))
        EXPECT_EQ(entry.path().filename().string().find(".tmp."), std::string::npos) << entry.path();
    for (const char* file : {"report.md", "junit.xml", "bounces.csv", "report.html"})
        EXPECT_TRUE(fs::is_regular_file(out / file)) << file << "\n" << r.output;

    // Finding 15's variant: --trajectories into a scenario folder that cannot
    // be one is found before anything runs.
    const fs::path traj = dir_ / "traj";
    fs::create_directories(traj);
    write_file("traj/seed-2d", "a file where the scenario's folder goes\n");
    const CliResult early = bouncecheck("run " + kScenarios + "/seed-2d.toml" +
                                        " --engines reference --trajectories --out " + traj.string());
    EXPECT_EQ(early.status, 2) << early.output;
    EXPECT_NE(early.output.find("--out: cannot create " + (traj / "seed-2d").string()), std::string::npos) << early.output;
    EXPECT_EQ(early.output.find("filesystem error"), std::string::npos) << early.output;
    EXPECT_FALSE(fs::exists(traj / "report.json"));
}

// The audit's question: a scenario file's [external.NAME] command is run by
// `run`. The choice: `validate` names every program a file would run, so a
// reviewer of a pull request sees it, and `run --no-scenario-programs`
// refuses such a file before anything runs (exit 2), for a CI job given
// scenario files nobody reviewed.
TEST_F(ExternalContainment, AScenarioFilesProgramsAreShownByValidateAndRefusedOnRequest) {
    const fs::path marker = dir_ / "it-ran";
    write_file("touch.sh", "touch '" + marker.string() + "'\n");
    const fs::path scenario = write_file("declares.toml", slurp(kScenarios + "/seed-2d.toml") +
                                                              "\n[external.mine]\ncommand = [\"/bin/sh\", \"touch.sh\"]\n");
    const CliResult shown = bouncecheck("validate " + scenario.string());
    EXPECT_EQ(shown.status, 0) << shown.output;
    EXPECT_NE(shown.output.find(scenario.string() + ": [external.mine] runs '/bin/sh touch.sh'"), std::string::npos)
        << shown.output;
    EXPECT_EQ(bouncecheck("validate " + kScenarios + "/seed-2d.toml").output.find("runs"), std::string::npos);

    const fs::path out = dir_ / "out";
    const CliResult refused =
        bouncecheck("run " + scenario.string() + " --engines reference --no-scenario-programs --out " + out.string());
    EXPECT_EQ(refused.status, 2) << refused.output;
    EXPECT_NE(refused.output.find(scenario.string() +
                                  ": [external.mine] command: would run '/bin/sh touch.sh': refused "
                                  "(--no-scenario-programs)"),
              std::string::npos)
        << refused.output;
    EXPECT_FALSE(fs::exists(marker));
    EXPECT_FALSE(fs::exists(out / "report.json"));
    const CliResult sweep = bouncecheck("sweep " + scenario.string() + " --engines reference --no-scenario-programs --out " +
                                        out.string());
    EXPECT_EQ(sweep.status, 2) << sweep.output;
    EXPECT_FALSE(fs::exists(marker));

    // Without the flag the program runs (and fails its row: it writes no trajectory).
    const CliResult ran = bouncecheck("run " + scenario.string() + " --engines reference --out " + out.string());
    EXPECT_EQ(ran.status, 3) << ran.output;
    EXPECT_TRUE(fs::exists(marker));
}

}  // namespace
}  // namespace bouncecheck
