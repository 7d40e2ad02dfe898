// Output folders that never mislead (platform/output_manifest.h): the
// manifest's format and limits, what a second write of the same kind
// removes, and what it never touches.
#include "platform/output_manifest.h"
#include "tests/support/cli.h"
#include "tests/support/test_directory.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <variant>

namespace fs = std::filesystem;

namespace bouncecheck {
namespace {

using test::bouncecheck;
using test::CliResult;

const std::string kScenarios = BOUNCECHECK_SCENARIO_DIR;

std::string parse_error(const std::string& text) {
    const auto parsed = parse_manifest(text);
    return std::holds_alternative<std::string>(parsed) ? std::get<std::string>(parsed) : "";
}

TEST(Manifest, FormatParsesBackToTheSameEntries) {
    Manifest m;
    m.entries = {{"run", 12, 5, "report.json"}, {"stress", 0, 0xfedcba9876543210ull, "stress-scenarios/mc-0001.toml"}};
    const auto parsed = parse_manifest(format_manifest(m));
    ASSERT_TRUE(std::holds_alternative<Manifest>(parsed)) << std::get<std::string>(parsed);
    const Manifest& back = std::get<Manifest>(parsed);
    ASSERT_EQ(back.entries.size(), 2u);
    EXPECT_EQ(back.entries[1].kind, "stress");
    EXPECT_EQ(back.entries[1].digest, 0xfedcba9876543210ull);
    EXPECT_EQ(back.entries[1].path, "stress-scenarios/mc-0001.toml");
    EXPECT_EQ(back.entries[0].digest, 5u);
}

TEST(Manifest, BadTextIsRefusedWithItsLineAndReason) {
    const std::string h = std::string(kManifestHeader) + "\n";
    const struct {
        std::string text, reason;
    } cases[] = {
        {"", "1: empty"},
        {"hello\n", "1: not a bouncecheck manifest"},
        {h + "run\t1\t0123456789abcdef\treport.json", "2: the last line is cut off"},
        {h + "run\t1\t0123456789abcdef\n", "2: 3 fields where 4 are expected"},
        {h + "run\t1\t0123456789abcdef\ta\tb\n", "2: more than 4 tab-separated fields"},
        {h + "# a comment\nbuild\t1\t2\treport.json\n", "3: kind: unknown kind"},
        {h + "run\t-1\t0123456789abcdef\treport.json\n", "2: size: not a whole number"},
        {h + "run\t99999999999999999999\t0123456789abcdef\treport.json\n", "2: size: not a whole number"},
        {h + "run\t1\t0123456789abcdeg\treport.json\n", "2: digest: not 16 hexadecimal digits"},
        {h + "run\t1\t12\treport.json\n", "2: digest: not 16 hexadecimal digits"},
        {h + "run\t1\t0123456789abcdef\t../etc/passwd\n", "2: path: path has a . or .. component"},
        {h + "run\t1\t0123456789abcdef\t/etc/passwd\n", "2: path: path is absolute"},
        {h + "run\t1\t0123456789abcdef\ta//b\n", "2: path: path has an empty component"},
        {h + "run\t1\t0123456789abcdef\ta b\n", "2: path: path holds a character"},
        {h + "run\t1\t0123456789abcdef\t" + kManifestFileName + "\n", "2: path: the manifest lists itself"},
        {h + "run\t1\t0123456789abcdef\ta\nrun\t1\t0123456789abcdef\ta\n", "3: path: listed twice"},
        {h + "run\t1\t0123456789abcdef\t" + std::string(5000, 'a') + "\n", "2: line longer than 4096 bytes"},
    };
    for (const auto& c : cases) {
        const std::string error = parse_error(c.text);
        EXPECT_EQ(error.rfind(c.reason, 0), 0u) << "text:\n" << c.text << "\nerror: " << error;
    }
}

class ManifestFolder : public test::TestDirectory {
protected:
    // A file the "command" wrote: distinct contents, so a rewrite changes its size.
    void put(const std::string& relative, const std::string& text) {
        fs::create_directories((dir_ / "out" / relative).parent_path());
        std::ofstream(dir_ / "out" / relative, std::ios::binary) << text;
    }
    OutputFolder open_out() {
        auto out = OutputFolder::open(dir_ / "out");
        EXPECT_TRUE(out.has_value());
        return std::move(*out);
    }
};

TEST_F(ManifestFolder, TheSameKindWrittenAgainRemovesOnlyItsOwnFilesNotRewritten) {
    {
        OutputFolder out = open_out();
        put("report.json", "1");
        put("seed-2d/ode.csv", "t,x\n");
        put("seed-2d/box2d.csv", "t,x\n");
        out.record("run", {"report.json", "seed-2d/ode.csv", "seed-2d/box2d.csv"});
    }
    put("notes.txt", "a user's file");  // never listed: never touched
    {
        OutputFolder out = open_out();
        put("stress.json", "{}");
        out.record("stress", {"stress.json"});  // another kind: the run's files stay
    }
    EXPECT_TRUE(fs::exists(dir_ / "out" / "seed-2d" / "ode.csv"));
    OutputFolder out = open_out();
    put("report.json", "22");
    const ManifestUpdate u = out.record("run", {"report.json"});
    EXPECT_EQ(u.removed, (std::vector<std::string>{"seed-2d/box2d.csv", "seed-2d/ode.csv"}));
    EXPECT_TRUE(u.changed.empty());
    EXPECT_FALSE(fs::exists(dir_ / "out" / "seed-2d")) << "the folder it left empty goes too";
    EXPECT_TRUE(fs::exists(dir_ / "out" / "notes.txt"));
    EXPECT_TRUE(fs::exists(dir_ / "out" / "stress.json"));
    EXPECT_TRUE(fs::exists(dir_ / "out" / "report.json"));
    const std::string line = format_manifest_update(u, "out");
    EXPECT_NE(line.find("removed 2 files an earlier run wrote in out and this one did not: seed-2d/box2d.csv, "
                        "seed-2d/ode.csv"),
              std::string::npos)
        << line;
}

TEST_F(ManifestFolder, AFileChangedSinceItWasWrittenIsLeftAndNamed) {
    {
        OutputFolder out = open_out();
        put("report.json", "1");
        put("bounces.csv", "1");
        out.record("run", {"report.json", "bounces.csv"});
    }
    put("bounces.csv", "edited by hand");
    OutputFolder out = open_out();
    put("report.json", "2");
    const ManifestUpdate u = out.record("run", {"report.json"});
    EXPECT_TRUE(u.removed.empty());
    EXPECT_EQ(u.changed, std::vector<std::string>{"bounces.csv"});
    EXPECT_TRUE(fs::exists(dir_ / "out" / "bounces.csv"));
    // No longer listed: a third run leaves it alone without a word.
    OutputFolder again = open_out();
    const ManifestUpdate v = again.record("run", {"report.json"});
    EXPECT_TRUE(v.removed.empty() && v.changed.empty());
    EXPECT_TRUE(fs::exists(dir_ / "out" / "bounces.csv"));
}

TEST_F(ManifestFolder, AHandWrittenManifestCannotReachOutsideTheFolder) {
    // A listed path through a symbolic link to a folder outside: not followed.
    fs::create_directories(dir_ / "outside");
    std::ofstream(dir_ / "outside" / "x.csv") << "precious";
    fs::create_directories(dir_ / "out");
    fs::create_directory_symlink(dir_ / "outside", dir_ / "out" / "link");
    // Its size and digest are right: only the link stands in the way.
    std::ofstream(dir_ / "out" / kManifestFileName)
        << kManifestHeader << "\nrun\t8\t" << fmt::format("{:016x}", *file_digest(dir_ / "outside" / "x.csv"))
        << "\tlink/x.csv\n";
    OutputFolder out = open_out();
    const ManifestUpdate u = out.record("run", {});
    EXPECT_TRUE(u.removed.empty());
    EXPECT_TRUE(fs::exists(dir_ / "outside" / "x.csv"));
}

TEST_F(ManifestFolder, AnUnreadableManifestOrFolderIsRefusedBeforeAnythingRuns) {
    const std::string seed = kScenarios + "/seed-2d.toml --engines reference";
    // Not a manifest: exit 2, naming the file and line, nothing written.
    fs::create_directories(dir_ / "bad");
    std::ofstream(dir_ / "bad" / kManifestFileName) << "report.json\n";
    CliResult r = bouncecheck("run " + seed + " --out " + (dir_ / "bad").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(std::string(kManifestFileName) + ":1: not a bouncecheck manifest"), std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "bad" / "report.json"));
    // A FIFO in its place: refused at once, not waited on.
    fs::create_directories(dir_ / "fifo");
    ASSERT_EQ(::mkfifo((dir_ / "fifo" / kManifestFileName).c_str(), 0600), 0);
    r = bouncecheck("run " + seed + " --out " + (dir_ / "fifo").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("not a regular file"), std::string::npos) << r.output;
    // Over the size limit (sparse: costs no disk): refused from its size.
    fs::create_directories(dir_ / "huge");
    ASSERT_EQ(::truncate(write_file("huge/" + std::string(kManifestFileName), "").c_str(),
                         static_cast<off_t>(kManifestMaxBytes + 1)),
              0);
    r = bouncecheck("run " + seed + " --out " + (dir_ / "huge").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("over the limit"), std::string::npos) << r.output;
    // --out under a plain file: found before any simulation runs.
    write_file("plain", "x");
    r = bouncecheck("run " + seed + " --out " + (dir_ / "plain" / "out").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("error: --out: cannot create"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("reference"), std::string::npos) << "nothing ran:\n" << r.output;
}

// The case: a second run into the same --out without --trajectories
// leaves no trajectory of the first beside its reports.
TEST_F(ManifestFolder, ASecondRunRemovesTheFirstRunsTrajectoriesAndSaysSo) {
    const std::string out = (dir_ / "out").string();
    CliResult r = bouncecheck("run " + kScenarios + "/seed-2d.toml --engines reference,exact --trajectories --out " + out);
    ASSERT_EQ(r.status, 0) << r.output;
    ASSERT_TRUE(fs::exists(dir_ / "out" / "seed-2d" / "reference.csv"));
    put("my-notes.md", "mine");
    r = bouncecheck("run " + kScenarios + "/seed-2d.toml --engines reference --out " + out);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "out" / "seed-2d"));
    EXPECT_TRUE(fs::exists(dir_ / "out" / "my-notes.md"));
    EXPECT_TRUE(fs::exists(dir_ / "out" / "report.html"));
    EXPECT_NE(r.output.find("removed 2 files an earlier run wrote in " + out +
                            " and this one did not: seed-2d/exact.csv, seed-2d/reference.csv"),
              std::string::npos)
        << r.output;
    // A diff into the run's folder adds its files and removes none of the run's.
    r = bouncecheck("diff " + out + " " + out + " --out " + out);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(dir_ / "out" / "report.json"));
    EXPECT_TRUE(fs::exists(dir_ / "out" / "diff.json"));
}

TEST_F(ManifestFolder, AWholeStressRunRemovesTheShardFileAnEarlierShardLeft) {
    const std::string out = (dir_ / "out").string();
    const std::string stress = "stress --engines reference --only dead-ball --monte-carlo 0 --out " + out;
    CliResult r = bouncecheck(stress + " --shard 1/2");
    ASSERT_TRUE(r.status == 0 || r.status == 1) << r.output;
    ASSERT_TRUE(fs::exists(dir_ / "out" / "shard.cbor"));
    r = bouncecheck(stress);
    ASSERT_TRUE(r.status == 0 || r.status == 1) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "out" / "shard.cbor")) << "a stale shard file could be merged by mistake";
    EXPECT_TRUE(fs::exists(dir_ / "out" / "stress.json"));
}

}  // namespace
}  // namespace bouncecheck
