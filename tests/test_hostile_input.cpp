// Hostile hand-written input through the real command: `bouncecheck validate
// FILE` and `bouncecheck run FILE` each exit 2 with located diagnostics
// (FILE:LINE:COLUMN: KEY: REASON) and run nothing; never a crash, a sanitizer
// report or a hang. The loader's own tests (test_scenario_loader.cpp) check
// each rule in detail; these check what a user sees.
#include "tests/support/cli.h"
#include "tests/support/test_directory.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace {

using bouncecheck::test::bouncecheck;
using bouncecheck::test::CliResult;
using bouncecheck::test::slurp;

const fs::path kScenarios = BOUNCECHECK_SCENARIO_DIR;
const fs::path kInvalid = fs::path(BOUNCECHECK_TEST_DATA) / "invalid";

// Each test writes its files in its own directory, removed afterwards.
class HostileInput : public bouncecheck::test::TestDirectory {
protected:
    fs::path write(const std::string& name, std::string_view text) const { return write_file(name, text); }

    // `validate FILE` and `run FILE` both exit 2, print every line of
    // `expected` (each a whole diagnostic or its start) and write no report.
    void expect_refused(const fs::path& file, const std::vector<std::string>& expected) const {
        const fs::path out = dir_ / "out";
        for (const std::string command : {"validate", "run"}) {
            SCOPED_TRACE(command + " " + file.string());
            const std::string args = command == "run" ? " --out " + out.string() : "";
            const CliResult r = bouncecheck(command + " " + file.string() + args);
            EXPECT_EQ(r.status, 2) << r.output;
            for (const std::string& line : expected)
                EXPECT_NE(r.output.find(line), std::string::npos) << "missing: " << line << "\ngot:\n" << r.output;
            EXPECT_FALSE(fs::exists(out / "report.json"));
        }
    }
};

// The bundled 3D seed with one line replaced: a real file with one hostile value.
std::string seed_with(std::string_view from, std::string_view to) {
    std::string text = slurp(kScenarios / "seed-3d.toml");
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

// The 1-based line of `text` on which `needle` starts.
int line_of(std::string_view text, std::string_view needle) {
    const std::size_t at = text.find(needle);
    EXPECT_NE(at, std::string_view::npos) << needle;
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

TEST_F(HostileInput, EmptyFile) {
    const fs::path file = write("empty.toml", "");
    expect_refused(file, {file.string() + ":1:1: name: missing required key",
                          file.string() + ":1:1: run: missing required table [run]"});
}

TEST_F(HostileInput, BinaryGarbage) {
    const fs::path file = kInvalid / "binary-garbage.toml";
    expect_refused(file, {file.string() + ":1:2: invalid UTF-8"});
    // Every byte value once, in order: the first that is not UTF-8 is 0x80,
    // on line 2 (after 0x0A) at column 0x80 - 0x0A = 118.
    std::string bytes;
    for (int c = 0; c < 256; ++c) bytes += static_cast<char>(c);
    const fs::path all = write("all-bytes.toml", bytes);
    expect_refused(all, {all.string() + ":2:118: invalid UTF-8"});
}

TEST_F(HostileInput, GigabyteNumberRefusedBeforeReading) {
    // A gigabyte: a number running into a sparse hole, cheap to make. Refused
    // by its size alone, before a byte is read, at 1:1.
    const fs::path file = write("huge.toml", "name = \"huge\"\n[ball]\nradius = 1");
    fs::resize_file(file, std::uintmax_t{1} << 30);
    expect_refused(file, {file.string() + ":1:1: file is 1073741824 bytes, larger than the limit of 1048576 bytes"});
}

TEST_F(HostileInput, DeeplyNestedTables) {
    std::string header = "[a";
    for (int i = 0; i < 100000; ++i) header += ".a";
    const fs::path dotted = write("dotted.toml", header + "]\n");
    expect_refused(dotted, {dotted.string() + ":1:2003: more than 1000 '.' outside strings and comments"});
    // Arrays and inline tables: toml++ stops at its own limit of 256 levels,
    // located at the value that goes one deeper.
    const fs::path arrays = write("arrays.toml", "name = " + std::string(100000, '[') + "\n");
    expect_refused(arrays, {arrays.string() + ":1:264: Error while parsing value: exceeded maximum nested value depth"});
    std::string inline_tables = "name = ";
    for (int i = 0; i < 100000; ++i) inline_tables += "{a=";
    const fs::path tables = write("tables.toml", inline_tables + "\n");
    expect_refused(tables, {tables.string() + ":1:776: Error while parsing value: exceeded maximum nested value depth"});
}

TEST_F(HostileInput, DuplicateKeysAndTables) {
    const std::string key_text = seed_with("radius = 0.05", "radius = 0.05\nradius = 0.06");
    const fs::path key = write("key.toml", key_text);
    // toml++ reports it at the second value, naming the key in its reason.
    expect_refused(key, {key.string() + ":" + std::to_string(line_of(key_text, "radius = 0.06")) +
                         ":10: Error while parsing key-value pair: cannot redefine existing floating-point 'radius'"});
    const std::string table_text = seed_with("[world]", "[ball]\n[world]");
    const fs::path table = write("table.toml", table_text);
    expect_refused(table, {table.string() + ":" + std::to_string(line_of(table_text, "[ball]\n[world]")) +
                           ":1: Error while parsing table header: cannot redefine existing table 'ball'"});
}

TEST_F(HostileInput, NegativeZeroWherePositiveIsRequired) {
    // -0.0 == 0: refused wherever a value must be > 0, and the sign is shown.
    const std::string text = seed_with("radius = 0.05", "radius = -0.0");
    const fs::path radius = write("radius.toml", text);
    expect_refused(radius, {radius.string() + ":" + std::to_string(line_of(text, "radius = -0.0")) +
                            ":10: ball.radius: must be > 0, got -0"});
    const std::string run = seed_with("dt = 0.03\nduration = 42.0", "dt = -0.0\nduration = -0.0");
    const fs::path times = write("times.toml", run);
    const std::string dt_line = std::to_string(line_of(run, "dt = -0.0"));
    const std::string duration_line = std::to_string(line_of(run, "duration = -0.0"));
    expect_refused(times, {times.string() + ":" + dt_line + ":6: run.dt: must be > 0, got -0",
                           times.string() + ":" + duration_line + ":12: run.duration: must be > 0, got -0"});
    const std::string room = seed_with("size = [1.0, 1.0, 1.0]", "size = [1.0, -0.0, 1.0]");
    const fs::path side = write("side.toml", room);
    expect_refused(side, {side.string() + ":" + std::to_string(line_of(room, "size = [")) +
                          ":14: room.size[1]: room side -0 must be larger than the ball's diameter"});
    // Where zero is allowed, -0.0 is zero: a ball at rest, no damping, no friction, a zero limit.
    std::string zero = seed_with("velocity = [0.3, 0.1, 0.2]", "velocity = [-0.0, -0.0, -0.0]");
    zero.replace(zero.find("normal = 0.8"), 12, "normal = -0.0");
    zero.replace(zero.find("friction = 0.00553855"), 21, "friction = -0.0");
    zero.replace(zero.find("trajectory_rms = 0.05"), 21, "trajectory_rms = -0.0");
    const CliResult r = bouncecheck("validate " + write("zero.toml", zero).string());
    EXPECT_EQ(r.status, 0) << r.output;
}

TEST_F(HostileInput, BallExactlyTheSizeOfTheRoom) {
    const std::string text = seed_with("size = [1.0, 1.0, 1.0]", "size = [0.1, 0.1, 0.1]");
    const fs::path file = write("tight.toml", text);
    const std::string line = std::to_string(line_of(text, "size = ["));
    std::vector<std::string> expected;
    for (const auto& [axis, column] : {std::pair{0, 9}, {1, 14}, {2, 19}})
        expected.push_back(file.string() + ":" + line + ":" + std::to_string(column) + ": room.size[" +
                           std::to_string(axis) + "]: room side 0.1 must be larger than the ball's diameter 2 x "
                                                  "radius = 0.1");
    expect_refused(file, expected);
}

TEST_F(HostileInput, RoomsOfExtremeSize) {
    const std::string tiny_room = seed_with("size = [1.0, 1.0, 1.0]", "size = [1e-300, 1.0, 1.0]");
    const fs::path tiny = write("tiny.toml", tiny_room);
    const std::string size_line = std::to_string(line_of(tiny_room, "size = ["));
    expect_refused(tiny, {tiny.string() + ":" + size_line + ":9: room.size[0]: room side 1e-300 must be larger"});
    // Everything scaled down to 1e-300 m: ODE used to abort on the ball's underflowing inertia.
    std::string scaled = seed_with("size = [1.0, 1.0, 1.0]", "size = [1e-300, 1e-300, 1e-300]");
    scaled.replace(scaled.find("radius = 0.05"), 13, "radius = 1e-301");
    scaled.replace(scaled.find("position = [0.5, 0.95, 0.5]"), 27, "position = [5e-301, 5e-301, 5e-301]");
    const fs::path small = write("small.toml", scaled);
    expect_refused(small, {small.string() + ":" + std::to_string(line_of(scaled, "radius = ")) +
                           ":10: ball.radius: 1e-301 m is below the limit of 1e-09 m"});
    const std::string huge_room = seed_with("size = [1.0, 1.0, 1.0]", "size = [1.0, 1.0, 1e300]");
    const fs::path huge = write("huge.toml", huge_room);
    expect_refused(huge, {huge.string() + ":" + size_line +
                          ":19: room.size[2]: magnitude of 1e+300 exceeds the limit of 1000000000000000"});
}

TEST_F(HostileInput, ScalesThatMadeEnginesAbort) {
    // Box2D asserted on a 2D ball of radius 1e-100 (its speeds, scaled by
    // 1/radius into floats, overflowed); ODE on a subnormal dt, and on a dt
    // of 1e-300 with a speed of 1e15.
    std::string text = slurp(kScenarios / "seed-2d.toml");
    text.replace(text.find("size = [1.0, 1.0]"), 17, "size = [1e-99, 1e-99]");
    text.replace(text.find("radius = 0.05"), 13, "radius = 1e-100");
    text.replace(text.find("position = [0.5, 0.95]"), 22, "position = [5e-100, 5e-100]");
    const fs::path box2d = write("box2d.toml", text);
    expect_refused(box2d, {box2d.string() + ":" + std::to_string(line_of(text, "radius = ")) +
                           ":10: ball.radius: 1e-100 m is below the limit"});
    // 1000 steps each, within the steps limit: only the dt floor refuses them.
    const std::string run = seed_with("dt = 0.03\nduration = 42.0", "dt = 5e-324\nduration = 5e-321");
    const fs::path ode = write("ode.toml", run);
    expect_refused(ode, {ode.string() + ":" + std::to_string(line_of(run, "dt = ")) +
                         ":6: run.dt: 5e-324 s is below the limit of 1e-09 s"});
    text = slurp(kScenarios / "seed-2d.toml");
    text.replace(text.find("velocity = [0.3, 0.0]"), 21, "velocity = [1e15, 0.0]");
    text.replace(text.find("dt = 0.03\nduration = 50.0"), 25, "dt = 1e-300\nduration = 1e-297");
    const fs::path fast = write("fast.toml", text);
    expect_refused(fast, {fast.string() + ":" + std::to_string(line_of(text, "dt = ")) +
                          ":6: run.dt: 1e-300 s is below the limit of 1e-09 s"});
}

TEST_F(HostileInput, NoSuchFileAndDirectory) {
    // No line to point at: the file name and the reason.
    const fs::path missing = dir_ / "no-such-file.toml";
    expect_refused(missing, {missing.string() + ": cannot open: no such file"});
    expect_refused(dir_, {dir_.string() + ": cannot open: is a directory, not a scenario file"});
}

// Every numeric field of a scenario, each written on a line of its own so
// that its diagnostic's location is known.
struct Field {
    std::string key;
    int line, column;
};

TEST_F(HostileInput, NanAndInfinityInEveryNumericField) {
    for (const std::string value : {"nan", "+inf", "-inf"}) {
        SCOPED_TRACE(value);
        std::string text = "name = \"non-finite\"\n";
        int line = 1;
        std::string table;
        std::vector<Field> fields;
        const auto add = [&](const std::string& line_text) {
            text += line_text + "\n";
            ++line;
        };
        const auto start = [&](const std::string& name) {
            table = name;
            add("[" + name + "]");
        };
        const auto scalar = [&](const std::string& key) {
            add(key + " = " + value);
            fields.push_back({table + "." + key, line, static_cast<int>(key.size()) + 4});
        };
        const auto vector = [&](const std::string& key) {
            add(key + " = [");
            for (int i = 0; i < 3; ++i) {
                add(value + ",");
                fields.push_back({table + "." + key + "[" + std::to_string(i) + "]", line, 1});
            }
            add("]");
        };
        start("room"), vector("size");
        start("ball"), scalar("radius"), vector("position"), vector("velocity");
        start("world"), vector("gravity");
        start("damping"), scalar("normal"), scalar("tangential");
        start("run"), scalar("dt"), scalar("duration");
        for (const std::string engine : {"bullet", "ode", "box2d"}) start("engines." + engine), scalar("friction");
        for (const std::string set : {"thresholds", "thresholds.exact"}) {
            start(set);
            for (const char* limit :
                 {"bounce_height_rel", "trajectory_rms", "trajectory_max", "restitution_abs", "tangential_abs"})
                scalar(limit);
        }
        ASSERT_EQ(fields.size(), 30u);
        const fs::path file = write("non-finite.toml", text);
        std::vector<std::string> expected;
        for (const Field& f : fields)
            expected.push_back(file.string() + ":" + std::to_string(f.line) + ":" + std::to_string(f.column) + ": " +
                               f.key + ": must be a finite number, got " + (value == "+inf" ? "inf" : value));
        expect_refused(file, expected);
        // The one integer field holds no nan or inf: it is reported as the wrong type.
        const std::string count_text =
            slurp(kScenarios / "seed-3d.toml") + "[thresholds.ode]\nbounce_count = " + value + "\n";
        const fs::path count = write("count.toml", count_text);
        expect_refused(count, {count.string() + ":" + std::to_string(line_of(count_text, "bounce_count = " + value)) +
                               ":16: thresholds.ode.bounce_count: expected an integer, got a floating-point number"});
    }
}

}  // namespace
