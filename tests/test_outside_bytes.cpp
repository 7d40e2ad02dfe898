// Bytes from outside that a run shows (an external program's stderr, its
// settings, a trajectory's header): whatever they hold, every report is
// written and valid, and none of them reaches a terminal, report.md or
// report.html raw (the hostile audit's findings 2, 6 and 16).
#include "external/external_simulator.h"
#include "platform/printable_text.h"
#include "tests/support/cli.h"
#include "tests/support/test_directory.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace fs = std::filesystem;

namespace bouncecheck {
namespace {

using test::bouncecheck;
using test::CliResult;
using test::slurp;

const std::string kScenarios = BOUNCECHECK_SCENARIO_DIR;

TEST(PrintableText, InvalidUtf8BecomesReplacementAndControlsBecomeEscapes) {
    EXPECT_EQ(printable_text("plain ascii, é and ✓"), "plain ascii, é and ✓");
    EXPECT_EQ(printable_text("\x1b[2Jclear"), "\\x1b[2Jclear");
    EXPECT_EQ(printable_text("tab\there\r"), "tab\\x09here\\x0d");
    EXPECT_EQ(printable_text("a\nb"), "a\\x0ab");
    EXPECT_EQ(printable_text("a\nb", /*keep_newlines=*/true), "a\nb");
    EXPECT_EQ(printable_text("\xff\xfe"), "\xEF\xBF\xBD\xEF\xBF\xBD");
    EXPECT_EQ(printable_text("\xc3"), "\xEF\xBF\xBD");                  // cut off
    EXPECT_EQ(printable_text("\xc0\xaf"), "\xEF\xBF\xBD\xEF\xBF\xBD");  // overlong '/'
    EXPECT_EQ(printable_text("\xed\xa0\x80"), "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD");  // a surrogate
    EXPECT_EQ(printable_text("\xc2\x9b"), "\\x9b");                     // C1 CSI, as a code point
    const std::string four_replacements = "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD";
    EXPECT_EQ(printable_text("\xf4\x90\x80\x80"), four_replacements);  // above U+10FFFF
}

// A JSON library error reads without its "[json.exception...]" prefix.
TEST(PrintableText, ErrorTextDropsTheJsonLibrarysPrefix) {
    try {
        const nlohmann::json parsed = nlohmann::json::parse("{\"a\": 1e400}");
        FAIL() << "1e400 parsed: " << parsed.dump();
    } catch (const std::exception& e) {
        EXPECT_EQ(std::string(e.what()).rfind("[json.exception.out_of_range.406] ", 0), 0u) << e.what();
        EXPECT_EQ(error_text(e).rfind("number overflow parsing '1e400'", 0), 0u) << error_text(e);
    }
    EXPECT_EQ(error_text(std::runtime_error("plain \x1b[2J")), "plain \\x1b[2J");
}

class OutsideBytes : public test::TestDirectory {};

TEST_F(OutsideBytes, AFailingExternalsStderrCostsOnlyItsRowAndReachesNoOutputRaw) {
    // stderr: bytes that are not UTF-8, a terminal escape that clears the
    // screen, and what blanked report.html when embedded as it was.
    const fs::path program = write_file("bad.sh",
                                        "printf 'broken \\377\\376 \\033[2J <!--<script> | </script> end\\n' >&2\n"
                                        "exit 1\n");
    const fs::path out = dir_ / "out";
    const CliResult r = bouncecheck("run " + kScenarios + "/seed-2d.toml --engines reference,exact --external 'bad=/bin/sh " +
                                    program.string() + "' --out " + out.string());
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_EQ(r.output.find('\x1b'), std::string::npos) << "a raw escape reached the terminal";
    EXPECT_NE(r.output.find("\\x1b[2J"), std::string::npos) << r.output;

    // Every report written; report.json parses, the bad bytes as U+FFFD.
    for (const char* file : {"report.json", "report.md", "junit.xml", "bounces.csv", "report.html"})
        EXPECT_TRUE(fs::exists(out / file)) << file;
    const nlohmann::json report = nlohmann::json::parse(slurp(out / "report.json"));
    std::string reason;
    for (const auto& sim : report["scenarios"][0]["simulators"])
        if (sim["simulator"] == "bad") reason = sim.at("reason").get<std::string>();
    EXPECT_NE(reason.find("broken \xEF\xBF\xBD\xEF\xBF\xBD \\x1b[2J"), std::string::npos) << reason;
    EXPECT_EQ(slurp(out / "report.md").find('\x1b'), std::string::npos);

    // report.html: the data block holds no "<" at all, so neither "<!--<script>"
    // nor "</script>" from the program can end or swallow the element.
    const std::string html = slurp(out / "report.html");
    const auto data = html.find("<script id=\"bouncecheck-data\" type=\"application/json\">");
    ASSERT_NE(data, std::string::npos);
    const auto body = data + std::string("<script id=\"bouncecheck-data\" type=\"application/json\">").size();
    const auto end = html.find("</script>", body);
    ASSERT_NE(end, std::string::npos);
    const std::string json_text = html.substr(body, end - body);
    EXPECT_EQ(json_text.find('<'), std::string::npos);
    EXPECT_NE(json_text.find("\\u003c!--\\u003cscript>"), std::string::npos);
    EXPECT_TRUE(nlohmann::json::accept(json_text));  // and it is still the run's JSON
}

// The settings file the harness hands an external is the program's to
// write: replaced by a FIFO it must not hang the run (the audit's finding 3),
// and grown past 1 MiB it must not be read whole into every report (4).
TEST_F(OutsideBytes, ASettingsFileReplacedByAFifoOrGrownHugeFailsOnlyItsRow) {
    const std::string example = std::string(BOUNCECHECK_EXAMPLES) + "/semi_implicit_euler.py";
    const auto program = [&](const std::string& name, const std::string& then) {
        return write_file(name, "import json, os, subprocess, sys\n"
                                "data = sys.stdin.read()\n"
                                "path = json.loads(data)['settings_file']\n"
                                "subprocess.run([sys.executable, '" + example + "'], input=data.encode(), check=True)\n"
                                "os.remove(path)\n" + then + "\n");
    };
    const struct {
        fs::path program;
        std::string reason;
    } cases[] = {
        {program("fifo.py", "os.mkfifo(path)"), "its settings file: not a regular file"},
        {program("huge.py", "open(path, 'w').write('[' + ' ' * (2 << 20) + ']')"),
         "its settings file: 2097154 bytes, over the limit of 1048576"},
    };
    for (const auto& c : cases) {
        const fs::path out = dir_ / c.program.stem();
        const CliResult r = bouncecheck("run " + kScenarios + "/seed-2d.toml --engines reference --external 'mine=python3 " +
                                        c.program.string() + "' --external-timeout 60 --out " + out.string());
        EXPECT_EQ(r.status, 3) << r.output;
        EXPECT_NE(r.output.find(c.reason), std::string::npos) << r.output;
        EXPECT_TRUE(fs::exists(out / "report.json")) << r.output;
    }
    EXPECT_THROW(parse_external_settings(std::string(20, '[') + std::string(20, ']')), std::runtime_error);
    try {
        parse_external_settings(std::string(20, '[') + std::string(20, ']'));
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "nested deeper than 8 levels");
    }
    EXPECT_EQ(parse_external_settings(R"([{"key": "k", "value": 1, "why": "w"}])").size(), 1u);
}

}  // namespace
}  // namespace bouncecheck
