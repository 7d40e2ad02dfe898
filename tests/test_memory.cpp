// `bouncecheck run` keeps its memory flat in the run's length: the reference
// and every metric stream, nothing is kept per step without --trajectories.
// The real binary runs in a child process and its peak resident set comes
// from wait4's rusage. A 1e8-step run takes about 10 s (the per-state
// metrics and the comparison against exact), too long for the suite, so the
// suite runs 1e5 and 1e7 steps: a hundredfold longer run must not raise the
// peak by more than 4 MB, and both stay under 50 MB. Keeping even one byte
// per step would add 10 MB at 1e7 steps, so 4 MB still catches any per-step
// growth, while the peak of one run moves by up to 1.5 MB with the machine
// (malloc's per-thread arenas follow which oneTBB threads happened to
// allocate; seen in CI). Each length runs twice and its lower peak counts.
// (Measured by hand for 1e8 steps: bench/README.md.)
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;

struct ChildRun {
    int exit_status = -1;
    long peak_rss_kb = 0;
};

// Runs the bouncecheck binary with `args`, output discarded.
ChildRun run_child(const std::vector<std::string>& args) {
    std::vector<char*> argv;
    std::string cli = BOUNCECHECK_CLI;
    argv.push_back(cli.data());
    std::vector<std::string> copies = args;
    for (auto& a : copies) argv.push_back(a.data());
    argv.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::freopen("/dev/null", "w", stdout);
        std::freopen("/dev/null", "w", stderr);
        ::execv(argv[0], argv.data());
        ::_exit(127);
    }
    ChildRun out;
    int status = 0;
    rusage usage{};
    if (pid > 0 && ::wait4(pid, &status, 0, &usage) == pid) {
        out.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        out.peak_rss_kb = usage.ru_maxrss;  // kilobytes on Linux
    }
    return out;
}

// The lower peak of two runs of `args`, both of which must exit 0.
long lower_peak_kb(const std::vector<std::string>& args, const std::string& label) {
    long lowest = 0;
    for (int attempt = 0; attempt < 2; ++attempt) {
        const ChildRun r = run_child(args);
        EXPECT_EQ(r.exit_status, 0) << label;
        EXPECT_GT(r.peak_rss_kb, 0) << label;
        if (attempt == 0 || r.peak_rss_kb < lowest) lowest = r.peak_rss_kb;
    }
    return lowest;
}

// The allowed rise of the peak between a short and a long run (see the top).
constexpr long kGrowthAllowanceKb = 4 * 1024;

// seed-3d with a duration of `steps` steps, written to `dir`.
fs::path long_scenario(const fs::path& dir, std::int64_t steps) {
    const fs::path file = dir / ("long-" + std::to_string(steps) + ".toml");
    std::ofstream(file) << "name = \"long\"\n"
                        << "[room]\nsize = [1.0, 1.0, 1.0]\n"
                        << "[ball]\nradius = 0.05\nposition = [0.5, 0.95, 0.5]\nvelocity = [0.3, 0.1, 0.2]\n"
                        << "[world]\ngravity = [0.0, 0.0, -0.0981]\n"
                        << "[damping]\nnormal = 0.8\ntangential = 0.99\n"
                        << "[run]\ndt = 0.03\nduration = " << 0.03 * static_cast<double>(steps) << "\n";
    return file;
}

// The ceiling on the peak. Under AddressSanitizer (scripts/sanitize.sh) its
// runtime's shadow memory and allocator add a fixed ~25 MB (74 MB measured);
// the growth check is the same in both builds.
#ifdef __SANITIZE_ADDRESS__
constexpr long kPeakCeilingKb = 128 * 1024;
#else
constexpr long kPeakCeilingKb = 50 * 1024;
#endif

TEST(Memory, ReferenceRunPeakDoesNotGrowWithRunLength) {
    const fs::path dir = fs::temp_directory_path() / ("bouncecheck-memory-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    long peak_kb[2] = {};
    const std::int64_t lengths[2] = {100000, 10000000};
    for (int k = 0; k < 2; ++k) {
        const std::string label = std::to_string(lengths[k]) + " steps";
        peak_kb[k] = lower_peak_kb(
            {"run", long_scenario(dir, lengths[k]).string(), "--engines", "reference", "--out", (dir / "out").string()},
            label);
        EXPECT_LT(peak_kb[k], kPeakCeilingKb) << label;
    }
    EXPECT_LT(peak_kb[1] - peak_kb[0], kGrowthAllowanceKb)
        << "peak RSS " << peak_kb[0] << " KB at 1e5 steps, " << peak_kb[1] << " KB at 1e7 steps";
    fs::remove_all(dir);
}

// An external simulator's rows stream through the harness (docs/external.md):
// nothing is kept per row, so a 30-fold longer run through the protocol does
// not raise the harness's peak either. The program is the C++ example
// wrapping the reference; the peak is bouncecheck's own or its program's,
// whichever is larger (wait4 reports the largest of the process and the
// children it reaped), and neither grows with the run.
TEST(Memory, ExternalRowsStreamWithoutGrowth) {
    const fs::path dir = fs::temp_directory_path() / ("bouncecheck-memory-ext-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    long peak_kb[2] = {};
    const std::int64_t lengths[2] = {100000, 3000000};
    for (int k = 0; k < 2; ++k) {
        const std::string label = std::to_string(lengths[k]) + " steps";
        peak_kb[k] = lower_peak_kb({"run", long_scenario(dir, lengths[k]).string(), "--engines", "reference",
                                    "--external", std::string("copy=") + BOUNCECHECK_ENGINE_EXAMPLE + " reference",
                                    "--out", (dir / "out").string()},
                                   label);
        EXPECT_LT(peak_kb[k], 2 * kPeakCeilingKb) << label;
    }
    EXPECT_LT(peak_kb[1] - peak_kb[0], kGrowthAllowanceKb)
        << "peak RSS " << peak_kb[0] << " KB at 1e5 steps, " << peak_kb[1] << " KB at 3e6 steps";
    fs::remove_all(dir);
}

}  // namespace
