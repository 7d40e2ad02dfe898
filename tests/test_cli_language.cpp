// One command-line language across the commands: comma lists with spaces
// trimmed and repeatable flags, the shared option names and their aliases,
// --no-timings wherever timings are written, "did you mean" for every
// refused name, --help's examples and exit codes, and `list`.
#include "platform/did_you_mean.h"
#include "tests/support/cli.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

using bouncecheck::test::CliResult;
using bouncecheck::test::bouncecheck;
using bouncecheck::test::slurp;

const std::string kScenarios = BOUNCECHECK_SCENARIO_DIR;
const std::string kSeed2d = kScenarios + "/seed-2d.toml";

fs::path fresh_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("bouncecheck-lang-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    return dir;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(DidYouMean, SuggestsTheClosestNameWithinATypo) {
    using bouncecheck::closest_name;
    const std::vector<std::string> keys = {"radius", "position", "velocity"};
    EXPECT_EQ(closest_name("positon", keys), "position");    // a deletion
    EXPECT_EQ(closest_name("Velocity", keys), "velocity");   // case
    EXPECT_EQ(closest_name("raidus", keys), "radius");       // a swap of neighbours
    EXPECT_EQ(closest_name("mass", keys), std::nullopt);     // nothing close
    EXPECT_EQ(closest_name("ode-ext", {"ode", "bullet"}), std::nullopt);  // four edits in seven letters
    EXPECT_EQ(closest_name("odee", {"ode", "bullet"}), "ode");
    EXPECT_EQ(closest_name(std::string(200, 'a'), keys), std::nullopt);  // no quadratic table for a long word
    EXPECT_EQ(bouncecheck::did_you_mean("refrence", {"reference", "exact"}), "; did you mean 'reference'?");
    EXPECT_EQ(bouncecheck::did_you_mean("zzz", {"reference", "exact"}), "");
}

TEST(CliLanguage, EngineListsTrimSpacesAndRepeat) {
    const fs::path a = fresh_dir("list-a"), b = fresh_dir("list-b"), c = fresh_dir("list-c");
    const std::string common = kSeed2d + " --no-timings --out ";
    ASSERT_EQ(bouncecheck("run --engines reference,exact " + common + a.string()).status, 0);
    const CliResult spaced = bouncecheck("run --engines \"reference, exact\" " + common + b.string());
    ASSERT_EQ(spaced.status, 0) << spaced.output;
    // Repeated, and before the positional scenario: the list takes one argument an occurrence.
    const CliResult repeated =
        bouncecheck("run --engines reference --engines ' exact' --no-timings --out " + c.string() + " " + kSeed2d);
    ASSERT_EQ(repeated.status, 0) << repeated.output;
    EXPECT_EQ(slurp(a / "report.json"), slurp(b / "report.json"));
    EXPECT_EQ(slurp(a / "report.json"), slurp(c / "report.json"));
    const auto report = nlohmann::json::parse(slurp(a / "report.json"));
    EXPECT_EQ(report["scenarios"][0]["simulators"].size(), 2u);
    for (const fs::path& dir : {a, b, c}) fs::remove_all(dir);
}

TEST(CliLanguage, UnknownSimulatorSuggestsTheClosest) {
    const CliResult r = bouncecheck("run " + kSeed2d + " --engines refrence --out " + fresh_dir("typo").string());
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.output, "unknown simulator 'refrence'; did you mean 'reference'?")) << r.output;
}

TEST(CliLanguage, ThresholdKeysAreAListWithSuggestions) {
    const fs::path out = fresh_dir("threshold");
    const CliResult ok = bouncecheck("run " + kSeed2d +
                                     " --engines reference --threshold 'bounce_height_rel=0.5, trajectory_rms=1' "
                                     "--out " + out.string());
    EXPECT_EQ(ok.status, 0) << ok.output;
    const CliResult typo =
        bouncecheck("run " + kSeed2d + " --engines reference --threshold trajectory_rsm=1 --out " + out.string());
    EXPECT_EQ(typo.status, 2);
    EXPECT_TRUE(contains(typo.output, "unknown key; did you mean 'trajectory_rms'?")) << typo.output;
    fs::remove_all(out);
}

TEST(CliLanguage, CalibrateTakesEnginesWithEngineAsAlias) {
    // Both spellings reach the same option: the refusal names the option and suggests.
    for (const char* flag : {"--engines", "--engine"}) {
        const CliResult r = bouncecheck("calibrate " + kSeed2d + " " + flag + " bulet");
        EXPECT_EQ(r.status, 2) << flag;
        EXPECT_TRUE(contains(r.output, "--engines: 'bulet' is not a built engine; did you mean 'bullet'?"))
            << flag << ": " << r.output;
    }
    const CliResult two = bouncecheck("calibrate " + kSeed2d + " --engines bullet,ode");
    EXPECT_EQ(two.status, 2);
    EXPECT_TRUE(contains(two.output, "calibrate tunes one engine at a time (2 given)")) << two.output;
}

// The rows of stress.csv (its first column), without the header.
std::multiset<std::string> stress_rows(const fs::path& dir) {
    std::multiset<std::string> rows;
    std::istringstream csv(slurp(dir / "stress.csv"));
    std::string line;
    std::getline(csv, line);
    while (std::getline(csv, line)) rows.insert(line.substr(0, line.find(',')));
    return rows;
}

TEST(CliLanguage, StressOnlyTakesCommasSpacesAndRepeatsAlike) {
    const fs::path a = fresh_dir("only-a"), b = fresh_dir("only-b"), c = fresh_dir("only-c");
    const std::string common = " --engines reference --monte-carlo 0 --no-timings --out ";
    ASSERT_EQ(bouncecheck("stress --only dead-ball,elastic" + common + a.string()).status, 0);
    ASSERT_EQ(bouncecheck("stress --only dead-ball elastic" + common + b.string()).status, 0);
    ASSERT_EQ(bouncecheck("stress --only 'dead-ball, ' --only elastic" + common + c.string()).status, 0);
    EXPECT_EQ(stress_rows(a), (std::multiset<std::string>{"dead-ball", "elastic"}));
    // --no-timings: the same input gives the same bytes.
    EXPECT_EQ(slurp(a / "stress.csv"), slurp(b / "stress.csv"));
    EXPECT_EQ(slurp(a / "stress.csv"), slurp(c / "stress.csv"));
    const auto json = nlohmann::json::parse(slurp(a / "stress.json"));
    EXPECT_TRUE(json["wall_seconds"].is_null());
    for (const auto& result : json["results"]) EXPECT_TRUE(result["run_seconds"].is_null()) << result.dump();

    const CliResult typo = bouncecheck("stress --only dead-bal" + common + a.string());
    EXPECT_EQ(typo.status, 2);
    EXPECT_TRUE(contains(typo.output, "no stress scenario or row 'dead-bal'; did you mean 'dead-ball'?")) << typo.output;
    for (const fs::path& dir : {a, b, c}) fs::remove_all(dir);
}

TEST(CliLanguage, SweepAndMergeLeaveTimingsOutAndMergeTakesOut) {
    const fs::path root = fresh_dir("sweep");
    const std::string sweep = "sweep " + kSeed2d + " --engines reference --dt '0.03, 0.015' --repeat 1 ";
    ASSERT_EQ(bouncecheck(sweep + "--no-timings --out " + (root / "a").string()).status, 0);
    ASSERT_EQ(bouncecheck(sweep + "--no-timings --out " + (root / "b").string()).status, 0);
    EXPECT_EQ(slurp(root / "a" / "sweep.csv"), slurp(root / "b" / "sweep.csv"));
    const auto json = nlohmann::json::parse(slurp(root / "a" / "sweep.json"));
    ASSERT_EQ(json["rows"].size(), 2u);
    for (const auto& row : json["rows"]) {
        EXPECT_TRUE(row["ns_per_step"].is_null()) << row.dump();
        EXPECT_TRUE(row["error"].is_number()) << row.dump();
    }
    EXPECT_FALSE(json["provenance"].contains("machine"));

    for (const char* k : {"1", "2"})
        ASSERT_EQ(bouncecheck(sweep + "--shard " + k + "/2 --out " + (root / ("shard-" + std::string(k))).string()).status, 0);
    const std::string shards = (root / "shard-1").string() + " " + (root / "shard-2").string();
    const CliResult flag = bouncecheck("merge --no-timings --out " + (root / "m1").string() + " " + shards);
    ASSERT_EQ(flag.status, 0) << flag.output;
    const CliResult positional = bouncecheck("merge --no-timings " + (root / "m2").string() + " " + shards);
    ASSERT_EQ(positional.status, 0) << positional.output;
    EXPECT_EQ(slurp(root / "m1" / "sweep.csv"), slurp(root / "a" / "sweep.csv"));
    EXPECT_EQ(slurp(root / "m2" / "sweep.csv"), slurp(root / "a" / "sweep.csv"));
    const CliResult none = bouncecheck("merge --out " + (root / "m3").string());
    EXPECT_EQ(none.status, 2);
    fs::remove_all(root);
}

TEST(CliLanguage, UnknownFlagsAndCommandsSuggestTheClosest) {
    const CliResult flag = bouncecheck("run --engins ode");
    EXPECT_EQ(flag.status, 2);
    EXPECT_TRUE(contains(flag.output, "unknown option '--engins' for run; did you mean '--engines'?")) << flag.output;
    const CliResult command = bouncecheck("strss");
    EXPECT_EQ(command.status, 2);
    EXPECT_TRUE(contains(command.output, "unknown command 'strss'; did you mean 'stress'?")) << command.output;
}

TEST(CliLanguage, HelpEndsWithExamplesAndExitCodes) {
    const CliResult r = bouncecheck("--help");
    EXPECT_EQ(r.status, 0);
    const auto examples = r.output.find("Examples:"), exits = r.output.find("Exit status of run");
    ASSERT_NE(examples, std::string::npos) << r.output;
    ASSERT_NE(exits, std::string::npos) << r.output;
    EXPECT_LT(examples, exits);
    for (const char* code : {"  0  ", "  1  ", "  2  ", "  3  "}) EXPECT_TRUE(contains(r.output.substr(exits), code));
    // Every example names a command that exists.
    EXPECT_TRUE(contains(r.output, "bouncecheck stress --only wall-starts,dead-ball"));
}

// Each command's --help ends with its own exit statuses, not run's.
TEST(CliLanguage, EachCommandsHelpEndsWithItsOwnExitStatuses) {
    const struct {
        const char* command;
        std::vector<std::string> own;  // a line each of its statuses must show
    } cases[] = {
        {"run", {"  1  a threshold was exceeded", "  3  a simulator failed"}},
        {"diff", {"  0  nothing changed beyond tolerance", "  1  something changed", "  3  an unexpected error"}},
        {"stress", {"  1  an invariant broke", "  3  a simulator crashed"}},
        {"sweep", {"  3  a pair failed"}},
        {"validate", {"  2  a file is not"}},
        {"merge", {"  2  the folders are not one complete run's shards"}},
    };
    for (const auto& c : cases) {
        const CliResult r = bouncecheck(std::string(c.command) + " --help");
        EXPECT_EQ(r.status, 0) << c.command;
        const auto exits = r.output.rfind("Exit status:");
        ASSERT_NE(exits, std::string::npos) << r.output;
        for (const std::string& line : c.own) EXPECT_TRUE(contains(r.output.substr(exits), line)) << c.command << ": " << line << "\n" << r.output;
        EXPECT_FALSE(contains(r.output, "Exit status of run") && std::string(c.command) != "run")
            << c.command << " shows run's statuses:\n" << r.output;
        EXPECT_FALSE(contains(r.output, "Examples:")) << c.command << ": the top level's examples\n" << r.output;
    }
}

TEST(CliLanguage, ListIsAlignedAndHasJson) {
    const CliResult text = bouncecheck("list");
    ASSERT_EQ(text.status, 0) << text.output;
    // Every row's second column starts where the others' do, whatever the name's length.
    std::istringstream lines(text.output);
    std::set<std::size_t> columns;
    for (std::string line; std::getline(lines, line);) {
        if (line.rfind("  ", 0) != 0) continue;
        const auto name_end = line.find(' ', 2);
        columns.insert(line.find_first_not_of(' ', name_end));
    }
    EXPECT_EQ(columns.size(), 1u) << text.output;

    const CliResult json = bouncecheck("list --json");
    ASSERT_EQ(json.status, 0) << json.output;
    const auto doc = nlohmann::json::parse(json.output);
    std::set<std::string> simulators, scenarios;
    for (const auto& s : doc["simulators"]) simulators.insert(s["name"].get<std::string>());
    for (const auto& s : doc["scenarios"]) scenarios.insert(s["name"].get<std::string>());
    EXPECT_TRUE(simulators.count("reference") && simulators.count("exact"));
    EXPECT_TRUE(scenarios.count("seed-2d-per-contact")) << json.output;
    EXPECT_EQ(doc["scenarios"][0]["dim"].get<int>() > 0, true);
}

}  // namespace

namespace bouncecheck {
namespace {

// Numbers on the command line are finite and in range, or refused before
// anything runs, the value named as typed (the hostile audit's finding 11:
// NaN passed CLI11's range checks, and 1e400 was printed in 309 digits).
TEST(CliLanguage, NumberOptionsRefuseNanInfinityAndTheOutOfRange) {
    const std::string seed = std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-2d.toml";
    const struct {
        std::string args, message;
    } cases[] = {
        {"run " + seed + " --engines reference --budget nan", "--budget: 'nan' is not a finite number"},
        {"run " + seed + " --engines reference --budget inf", "--budget: 'inf' is not a finite number"},
        {"run " + seed + " --engines reference --budget 1e400", "--budget: '1e400' is not a finite number"},
        {"run " + seed + " --engines reference --external-timeout nan", "--external-timeout: 'nan' is not a finite"},
        {"run " + seed + " --engines reference --external-timeout 1e10", "--external-timeout: 1e10 is outside [0.001, 1e+06]"},
        {"stress --only dead-ball --budget nan", "--budget: 'nan' is not a finite number"},
        {"sweep " + seed + " --budget -nan", "--budget: '-nan' is not a finite number"},
        {"calibrate " + seed + " --engines ode --max-mu nan", "--max-mu: 'nan' is not a finite number"},
        {"diff a b --timing-ratio nan", "--timing-ratio: 'nan' is not a finite number"},
        // Finding 20: a seed out of range was clamped to 2^64 - 1 without a word.
        {"stress --only dead-ball --seed -1", "--seed: '-1' is not a whole number from 0 to 18446744073709551615"},
        {"stress --only dead-ball --seed 18446744073709551616", "--seed: '18446744073709551616' is not a whole number"},
        {"stress --only dead-ball --seed 1e23", "--seed: '1e23' is not a whole number"},
    };
    for (const auto& c : cases) {
        const test::CliResult r = test::bouncecheck(c.args);
        EXPECT_EQ(r.status, 2) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << "\n" << r.output;
        EXPECT_EQ(r.output.find("00000000000000000000"), std::string::npos) << r.output;
    }
}

}  // namespace
}  // namespace bouncecheck
