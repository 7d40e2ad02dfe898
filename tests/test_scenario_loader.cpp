// Scenario loading and validation: the bundled scenarios, one test per
// validation rule (with its reported location, key and reason), and inputs
// that must produce ScenarioError and nothing else.
#include "scenarios/loader.h"
#include "tests/support/test_directory.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <bit>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {
namespace {

namespace fs = std::filesystem;

const fs::path kScenarioDir = BOUNCECHECK_SCENARIO_DIR;
const fs::path kInvalidDir = fs::path(BOUNCECHECK_TEST_DATA) / "invalid";

// A valid 3D scenario; tests edit one line of it. Positions below refer to it:
// line 5 is `radius = 0.05` (value at column 10), line 6 `position = [...]`
// (array at column 12, elements at 13, 18, 23).
constexpr std::string_view kValid = R"(name = "unit"
[room]
size = [1.0, 1.0, 1.0]
[ball]
radius = 0.05
position = [0.5, 0.5, 0.5]
velocity = [0.3, 0.1, 0.2]
[world]
gravity = [0.0, 0.0, -9.81]
[damping]
normal = 0.8
tangential = 0.99
[run]
dt = 0.03
duration = 1.0
)";

constexpr int kAnyColumn = -1;

// `base` with the single occurrence of `from` replaced by `to`.
std::string with(std::string_view from, std::string_view to, std::string_view base = kValid) {
    std::string text(base);
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "not in the base text: " << from;
    EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "ambiguous edit: " << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

// The diagnostics parse_scenario reports for `text`; a test failure if it accepts it.
std::vector<Diagnostic> errors_of(std::string_view text, const std::string& file = "test.toml") {
    try {
        parse_scenario(text, file);
    } catch (const ScenarioError& e) {
        return e.diagnostics();
    }
    ADD_FAILURE() << "accepted an invalid scenario:\n" << text;
    return {};
}

std::vector<Diagnostic> load_errors_of(const fs::path& file) {
    try {
        load_scenario(file);
    } catch (const ScenarioError& e) {
        return e.diagnostics();
    }
    ADD_FAILURE() << "accepted " << file;
    return {};
}

std::string dump(const std::vector<Diagnostic>& diagnostics) {
    std::string out;
    for (const Diagnostic& d : diagnostics) {
        out += "\n  ";
        out += d.format();
    }
    return diagnostics.empty() ? " (none)" : out;
}

// Whether one of `diagnostics` has this key, position and a reason containing `reason_part`.
::testing::AssertionResult has_error(const std::vector<Diagnostic>& diagnostics, std::string_view key, int line,
                                     int column, std::string_view reason_part) {
    for (const Diagnostic& d : diagnostics) {
        if (d.key == key && d.line == line && (column == kAnyColumn || d.column == column) &&
            d.reason.find(reason_part) != std::string::npos)
            return ::testing::AssertionSuccess();
    }
    return ::testing::AssertionFailure() << "no diagnostic `" << key << "` at " << line << ":" << column
                                         << " containing \"" << reason_part << "\"; got:" << dump(diagnostics);
}

// The only diagnostic of `text`, which must match.
::testing::AssertionResult single_error(std::string_view text, std::string_view key, int line, int column,
                                        std::string_view reason_part) {
    const std::vector<Diagnostic> diagnostics = errors_of(text);
    if (diagnostics.size() != 1)
        return ::testing::AssertionFailure() << "expected exactly one diagnostic, got:" << dump(diagnostics);
    return has_error(diagnostics, key, line, column, reason_part);
}

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// A file under the test's own temporary directory, removed afterwards.
class ScenarioLoaderFiles : public test::TestDirectory {
protected:
    void TearDown() override {
        std::error_code ec;
        fs::permissions(file_, fs::perms::owner_all, ec);  // a test may have made it unreadable
        TestDirectory::TearDown();
    }
    const fs::path& write(std::string_view text) {
        file_ = write_file("scenario.toml", text);
        return file_;
    }

    fs::path file_;
};

// --- The bundled scenarios --------------------------------------------------

TEST(ScenarioLoaderSeed, Loads2D) {
    const fs::path file = kScenarioDir / "seed-2d.toml";
    const Scenario s = load_scenario(file);
    EXPECT_EQ(s.name, "seed-2d");
    EXPECT_EQ(s.description,
              "The seed document's 2D simulation: a 5 cm ball released at the ceiling of a 1 m x 1 m room, "
              "moving right at 0.3 m/s, under 0.0981 m/s^2.");
    EXPECT_EQ(s.source, file);
    EXPECT_EQ(s.dim, 2);
    EXPECT_EQ(s.vertical_axis(), 1);
    EXPECT_EQ(s.room, Vec3(1.0, 1.0, 0.0));
    EXPECT_EQ(s.radius, 0.05);
    EXPECT_EQ(s.position, Vec3(0.5, 0.95, 0.0));
    EXPECT_EQ(s.velocity, Vec3(0.3, 0.0, 0.0));
    EXPECT_EQ(s.gravity, Vec3(0.0, -0.0981, 0.0));
    EXPECT_EQ(s.alpha, 0.8);
    EXPECT_EQ(s.beta, 0.99);
    EXPECT_EQ(s.dt, 0.03);
    EXPECT_EQ(s.duration, 50.0);
}

TEST(ScenarioLoaderSeed, Loads3D) {
    const fs::path file = kScenarioDir / "seed-3d.toml";
    const Scenario s = load_scenario(file);
    EXPECT_EQ(s.name, "seed-3d");
    EXPECT_EQ(s.description,
              "The seed document's 3D simulation: a 5 cm ball starting against the back wall (y = 1 - r) of a "
              "1 m cube, moving at (0.3, 0.1, 0.2) m/s, under 0.0981 m/s^2.");
    EXPECT_EQ(s.source, file);
    EXPECT_EQ(s.dim, 3);
    EXPECT_EQ(s.vertical_axis(), 2);
    EXPECT_EQ(s.room, Vec3(1.0, 1.0, 1.0));
    EXPECT_EQ(s.radius, 0.05);
    EXPECT_EQ(s.position, Vec3(0.5, 0.95, 0.5));
    EXPECT_EQ(s.velocity, Vec3(0.3, 0.1, 0.2));
    EXPECT_EQ(s.gravity, Vec3(0.0, 0.0, -0.0981));
    EXPECT_EQ(s.alpha, 0.8);
    EXPECT_EQ(s.beta, 0.99);
    EXPECT_EQ(s.dt, 0.03);
    EXPECT_EQ(s.duration, 42.0);
}

// Reproducing the reference bit for bit needs the doubles nearest the literals.
TEST(ScenarioLoaderSeed, ValuesAreTheNearestDoubles) {
    const Scenario s = load_scenario(kScenarioDir / "seed-3d.toml");
    EXPECT_EQ(bits(s.position.y()), bits(0.95));
    EXPECT_EQ(bits(s.gravity.z()), bits(-0.0981));
    EXPECT_EQ(bits(s.dt), bits(0.03));
    EXPECT_EQ(bits(s.beta), bits(0.99));
}

// --- Valid variations ---------------------------------------------------------

TEST(ScenarioLoaderValid, BaseTextLoads) {
    const Scenario s = parse_scenario(kValid, "in-memory.toml");
    EXPECT_EQ(s.name, "unit");
    EXPECT_EQ(s.description, "");
    EXPECT_EQ(s.source, fs::path("in-memory.toml"));
    EXPECT_EQ(s.gravity, Vec3(0.0, 0.0, -9.81));
}

TEST(ScenarioLoaderValid, IntegerLiteralsAccepted) {
    std::string text = with("size = [1.0, 1.0, 1.0]", "size = [2, 3, 4]");
    text = with("normal = 0.8", "normal = 1", text);
    text = with("tangential = 0.99", "tangential = 0", text);
    text = with("duration = 1.0", "duration = 10", text);
    const Scenario s = parse_scenario(text, "ints.toml");
    EXPECT_EQ(s.room, Vec3(2.0, 3.0, 4.0));
    EXPECT_EQ(s.alpha, 1.0);
    EXPECT_EQ(s.beta, 0.0);
    EXPECT_EQ(s.duration, 10.0);
}

TEST(ScenarioLoaderValid, BoundaryValuesAccepted) {
    // Touching walls on every axis, damping at both ends of [0, 1], dt == duration.
    std::string text = with("position = [0.5, 0.5, 0.5]", "position = [0.05, 0.95, 0.05]");
    text = with("normal = 0.8", "normal = 0.0", text);
    text = with("tangential = 0.99", "tangential = 1.0", text);
    text = with("dt = 0.03", "dt = 1.0", text);
    const Scenario s = parse_scenario(text, "edges.toml");
    EXPECT_EQ(s.position, Vec3(0.05, 0.95, 0.05));
    EXPECT_EQ(s.dt, s.duration);
}

TEST(ScenarioLoaderValid, DescriptionAndTomlSpellingsAccepted) {
    // Dotted keys and inline tables are the same document to TOML.
    std::string text = with("name = \"unit\"\n[room]\nsize = [1.0, 1.0, 1.0]\n",
                            "name = \"v1.2_test-A\"\ndescription = 'A \"quoted\" description.'\n"
                            "room.size = [1.0, 1.0, 1.0]\nrun = {dt = 0.03, duration = 1.0}\n");
    text = with("[run]\ndt = 0.03\nduration = 1.0\n", "", text);
    const Scenario s = parse_scenario(text, "spellings.toml");
    EXPECT_EQ(s.name, "v1.2_test-A");
    EXPECT_EQ(s.description, "A \"quoted\" description.");
    EXPECT_EQ(s.room, Vec3(1.0, 1.0, 1.0));
    EXPECT_EQ(s.dt, 0.03);
}

// --- One test per validation rule ---------------------------------------------

TEST(ScenarioLoaderInvalid, MissingTable) {
    const std::string text = with("[world]\ngravity = [0.0, 0.0, -9.81]\n", "");
    EXPECT_TRUE(single_error(text, "world", 1, 1, "missing required table [world]"));
}

TEST(ScenarioLoaderInvalid, MissingKeyPointsAtItsTable) {
    EXPECT_TRUE(single_error(with("radius = 0.05\n", ""), "ball.radius", 4, 1, "missing required key"));
}

TEST(ScenarioLoaderInvalid, MissingName) {
    EXPECT_TRUE(single_error(with("name = \"unit\"\n", ""), "name", 1, 1, "missing required key"));
}

TEST(ScenarioLoaderInvalid, UnknownTopLevelKey) {
    EXPECT_TRUE(single_error(with("name = \"unit\"\n", "name = \"unit\"\ncolour = \"red\"\n"), "colour", 2, 1,
                             "unknown key"));
}

TEST(ScenarioLoaderInvalid, UnknownKeyInTable) {
    EXPECT_TRUE(single_error(with("radius = 0.05\n", "radius = 0.05\nmass = 1.0\n"), "ball.mass", 6, 1,
                             "unknown key"));
}

TEST(ScenarioLoaderInvalid, UnknownSubTable) {
    const std::string text = std::string(kValid) + "[run.spin]\nrate = 1\n";
    EXPECT_TRUE(single_error(text, "run.spin", 16, 6, "unknown key"));
}

TEST(ScenarioLoaderInvalid, UnknownKeyIsQuotedAndEscaped) {
    // The key stays on one line and reads back as TOML.
    const std::string text = with("name = \"unit\"\n", "name = \"unit\"\n\"odd key\\n\" = 1\n");
    EXPECT_TRUE(single_error(text, "\"odd key\\u000A\"", 2, 1, "unknown key"));
}

TEST(ScenarioLoaderInvalid, EngineTableRejectsUnknownKeys) {
    const std::string text = std::string(kValid) + "[engines.box2d]\nenabled = true\n";
    EXPECT_TRUE(single_error(text, "engines.box2d.enabled", 17, 1, "unknown key"));
}

TEST(ScenarioLoaderInvalid, UnknownKeySuggestsTheClosestAndListsTheTablesKeys) {
    const std::string text = with("radius = 0.05\n", "radius = 0.05\npositon = 1.0\n");
    EXPECT_TRUE(single_error(text, "ball.positon", 6, 1,
                             "unknown key; did you mean 'position'? (keys of [ball]: radius, position, velocity)"));
}

TEST(ScenarioLoaderInvalid, EngineKeyTypoSuggestsTheSetting) {
    const std::string text = std::string(kValid) + "[engines.ode]\nfricton = 0.5\n";
    const std::vector<Diagnostic> d = errors_of(text);
    ASSERT_EQ(d.size(), 1u) << dump(d);
    EXPECT_TRUE(has_error(d, "engines.ode.fricton", 17, 1, "unknown key; did you mean 'friction'? (keys of [engines.ode]:"));
    EXPECT_NE(d[0].reason.find("tangential_model"), std::string::npos) << d[0].reason;
}

TEST(ScenarioLoaderInvalid, UnknownEngineSuggestsTheClosestOrHowToDeclareAnExternal) {
    const std::string typo = std::string(kValid) + "[engines.bulet]\nfriction = 0.5\n";
    EXPECT_TRUE(single_error(typo, "engines.bulet", 16, 10, "unknown engine; did you mean 'bullet'?"));
    // Nothing close: most likely a program from outside the build that was never declared.
    const std::string external = std::string(kValid) + "[engines.ode-ext]\nfriction = 0.5\n";
    EXPECT_TRUE(single_error(external, "engines.ode-ext", 16, 10,
                             "a simulator from outside the build is declared with --external ode-ext=COMMAND or an "
                             "[external.ode-ext] table"));
}

TEST(ScenarioLoaderValid, EngineTablesAreRead) {
    const std::string text = std::string(kValid) +
                             "[engines.bullet]\ntangential_model = \"friction\"\nfriction = 0.25\nrotation = \"locked\"\n"
                             "[engines.ode]\ntangential_model = \"per-contact\"\n";
    const Scenario s = parse_scenario(text, "engines.toml");
    ASSERT_EQ(s.engines.size(), 2u);
    EXPECT_EQ(s.engine_options("bullet").tangential_model, TangentialModel::friction);
    EXPECT_EQ(s.engine_options("bullet").friction, 0.25);
    EXPECT_FALSE(s.engine_options("bullet").free_rotation);
    EXPECT_EQ(s.engine_options("ode").tangential_model, TangentialModel::per_contact);
    EXPECT_TRUE(s.engine_options("ode").free_rotation);
    // An engine without a table runs with the defaults.
    EXPECT_EQ(s.engine_options("box2d").tangential_model, TangentialModel::friction);
    EXPECT_EQ(s.engine_options("box2d").friction, 0.0);
}

TEST(ScenarioLoaderInvalid, EngineTableValues) {
    EXPECT_TRUE(single_error(std::string(kValid) + "[engines.warp]\nfriction = 0.1\n", "engines.warp", 16, 10,
                             "unknown engine"));
    EXPECT_TRUE(single_error(std::string(kValid) + "[engines.ode]\ntangential_model = \"sticky\"\n",
                             "engines.ode.tangential_model", 17, 20, "must be \"friction\" or \"per-contact\""));
    EXPECT_TRUE(single_error(std::string(kValid) + "[engines.ode]\nfriction = -1\n", "engines.ode.friction", 17, 12,
                             "within [0, 10]"));
    EXPECT_TRUE(single_error(std::string(kValid) + "[engines.ode]\ntangential_model = \"per-contact\"\nfriction = 0.1\n",
                             "engines.ode.friction", 18, 12, "applies only with"));
    EXPECT_TRUE(single_error(std::string(kValid) + "[engines.box2d]\nrotation = \"spinning\"\n",
                             "engines.box2d.rotation", 17, 12, "\"free\" or \"locked\""));
    EXPECT_TRUE(single_error(with("name = \"unit\"\n", "engines = 3\nname = \"unit\"\n"), "engines", 1, 11,
                             "expected a table"));
}

TEST(ScenarioLoaderValid, ThresholdTablesAreRead) {
    const std::string text = std::string(kValid) +
                             "[thresholds]\nbounce_count = 5\nbounce_height_rel = 0.05\ntrajectory_rms = 0.05\n"
                             "trajectory_max = 0.2\nrestitution_abs = 0.02\ntangential_abs = 0.02\n"
                             "[thresholds.bullet]\ntrajectory_rms = 0.08\nbounce_count = 3\n";
    const Scenario s = parse_scenario(text, "thresholds.toml");
    const ThresholdSet& all = s.thresholds.all;
    EXPECT_EQ(all.bounce_count, 5);
    EXPECT_EQ(all.bounce_height_rel, 0.05);
    EXPECT_EQ(all.trajectory_rms, 0.05);
    EXPECT_EQ(all.trajectory_max, 0.2);
    EXPECT_EQ(all.restitution_abs, 0.02);
    EXPECT_EQ(all.tangential_abs, 0.02);
    ASSERT_EQ(s.thresholds.simulator.size(), 1u);
    const ThresholdSet& bullet = s.thresholds.simulator.at("bullet");
    EXPECT_EQ(bullet.trajectory_rms, 0.08);
    EXPECT_EQ(bullet.bounce_count, 3);
    EXPECT_FALSE(bullet.trajectory_max);
    // The override wins where it sets a limit; every other limit is inherited.
    const ThresholdSet merged = s.thresholds.for_simulator("bullet");
    EXPECT_EQ(merged.trajectory_rms, 0.08);
    EXPECT_EQ(merged.bounce_count, 3);
    EXPECT_EQ(merged.bounce_height_rel, 0.05);
    EXPECT_EQ(merged.trajectory_max, 0.2);
    EXPECT_EQ(merged.restitution_abs, 0.02);
    EXPECT_EQ(merged.tangential_abs, 0.02);
    // A simulator without a table gets [thresholds] as it is.
    EXPECT_EQ(s.thresholds.for_simulator("ode").trajectory_rms, 0.05);
    EXPECT_EQ(s.thresholds.for_simulator("ode").bounce_count, 5);
}

TEST(ScenarioLoaderValid, ThresholdsAbsentLeaveEveryLimitUnset) {
    const Scenario s = parse_scenario(kValid, "no-thresholds.toml");
    EXPECT_TRUE(s.thresholds.simulator.empty());
    for (const std::string simulator : {"reference", "exact", "bullet", "ode", "box2d"}) {
        SCOPED_TRACE(simulator);
        const ThresholdSet set = s.thresholds.for_simulator(simulator);
        EXPECT_FALSE(set.bounce_count);
        EXPECT_FALSE(set.bounce_height_rel);
        EXPECT_FALSE(set.trajectory_rms);
        EXPECT_FALSE(set.trajectory_max);
        EXPECT_FALSE(set.restitution_abs);
        EXPECT_FALSE(set.tangential_abs);
    }
}

TEST(ScenarioLoaderValid, ThresholdOverridesAloneAndBoundaryValues) {
    // Only per-simulator tables, every known simulator, dotted and inline spellings, integer limits, both ends of
    // the bounce_count range and limits of 0.
    const std::string text = std::string(kValid) +
                             "[thresholds.reference]\nbounce_count = 1\n"
                             "[thresholds.exact]\nbounce_count = 10000\n"
                             "[thresholds.ode]\ntrajectory_max = 1\nrestitution_abs = 0\n"
                             "[thresholds]\nbox2d = {}\n"
                             "bullet.tangential_abs = 0.0\nbullet.bounce_height_rel = 0.1\n";
    const Scenario s = parse_scenario(text, "overrides.toml");
    EXPECT_FALSE(s.thresholds.all.bounce_count);
    EXPECT_FALSE(s.thresholds.all.trajectory_max);
    EXPECT_EQ(s.thresholds.simulator.size(), 5u);
    EXPECT_EQ(s.thresholds.for_simulator("reference").bounce_count, 1);
    EXPECT_EQ(s.thresholds.for_simulator("exact").bounce_count, 10000);
    EXPECT_EQ(s.thresholds.for_simulator("ode").trajectory_max, 1.0);
    EXPECT_EQ(s.thresholds.for_simulator("ode").restitution_abs, 0.0);
    EXPECT_FALSE(s.thresholds.for_simulator("box2d").trajectory_rms);
    EXPECT_EQ(s.thresholds.for_simulator("bullet").tangential_abs, 0.0);
    EXPECT_EQ(s.thresholds.for_simulator("bullet").bounce_height_rel, 0.1);
}

TEST(ScenarioLoaderInvalid, ThresholdTableRejectsUnknownKeys) {
    EXPECT_TRUE(single_error(std::string(kValid) + "[thresholds]\nposition = 1e-9\n", "thresholds.position", 17, 1,
                             "unknown key"));
    EXPECT_TRUE(single_error(std::string(kValid) + "[thresholds.ode]\nenabled = true\n", "thresholds.ode.enabled", 17,
                             1, "unknown key"));
    EXPECT_TRUE(single_error(std::string(kValid) + "[thresholds.bullet.box2d]\ntrajectory_rms = 0.1\n",
                             "thresholds.bullet.box2d", 16, 20, "unknown key"));
}

TEST(ScenarioLoaderInvalid, ThresholdUnknownSimulator) {
    EXPECT_TRUE(single_error(std::string(kValid) + "[thresholds.warp]\ntrajectory_rms = 0.1\n", "thresholds.warp", 16,
                             13,
                             "unknown simulator (known: reference, exact, bullet, ode, box2d, mujoco, chipmunk, siconos, "
                             "siconos-ed, dart, rapier, jolt, physx, havok, box2d3, mujoco3, planck, p2, oimo, cannon, "
                             "ammo, matter, box2d-wasm)"));
    EXPECT_TRUE(single_error(std::string(kValid) + "[thresholds]\nBullet = {trajectory_rms = 0.1}\n",
                             "thresholds.Bullet", 17, 1, "unknown simulator"));
}

TEST(ScenarioLoaderInvalid, ThresholdNotATable) {
    EXPECT_TRUE(single_error(std::string(kValid) + "[thresholds]\nbullet = 3\n", "thresholds.bullet", 17, 10,
                             "expected a table, got an integer"));
    EXPECT_TRUE(single_error(with("name = \"unit\"\n", "thresholds = 0.05\nname = \"unit\"\n"), "thresholds", 1, 14,
                             "expected a table, got a floating-point number"));
    // A limit written as a table is a type error, not a simulator's table.
    EXPECT_TRUE(single_error(std::string(kValid) + "[thresholds.trajectory_rms]\nbullet = 0.1\n",
                             "thresholds.trajectory_rms", 16, 1, "expected a number, got a table"));
}

TEST(ScenarioLoaderInvalid, ThresholdBounceCount) {
    const std::string table = std::string(kValid) + "[thresholds]\n";
    EXPECT_TRUE(single_error(table + "bounce_count = 5.0\n", "thresholds.bounce_count", 17, 16,
                             "expected an integer, got a floating-point number"));
    EXPECT_TRUE(single_error(table + "bounce_count = \"5\"\n", "thresholds.bounce_count", 17, 16,
                             "expected an integer, got a string"));
    EXPECT_TRUE(single_error(table + "bounce_count = 0\n", "thresholds.bounce_count", 17, 16,
                             "must be within [1, 10000], got 0"));
    EXPECT_TRUE(single_error(table + "bounce_count = 10001\n", "thresholds.bounce_count", 17, 16,
                             "must be within [1, 10000], got 10001"));
    EXPECT_TRUE(single_error(table + "bounce_count = -9223372036854775808\n", "thresholds.bounce_count", 17, 16,
                             "got -9223372036854775808"));
    EXPECT_TRUE(single_error(std::string(kValid) + "[thresholds.ode]\nbounce_count = 2.5\n",
                             "thresholds.ode.bounce_count", 17, 16, "expected an integer"));
}

TEST(ScenarioLoaderInvalid, ThresholdLimits) {
    const std::string table = std::string(kValid) + "[thresholds]\n";
    EXPECT_TRUE(single_error(table + "bounce_height_rel = -0.05\n", "thresholds.bounce_height_rel", 17, 21,
                             "must be >= 0, got -0.05"));
    EXPECT_TRUE(single_error(table + "trajectory_rms = -1\n", "thresholds.trajectory_rms", 17, 18,
                             "must be >= 0, got -1"));
    EXPECT_TRUE(single_error(table + "trajectory_max = \"0.2\"\n", "thresholds.trajectory_max", 17, 18,
                             "expected a number, got a string"));
    EXPECT_TRUE(single_error(table + "restitution_abs = true\n", "thresholds.restitution_abs", 17, 19,
                             "expected a number, got a boolean"));
    EXPECT_TRUE(single_error(table + "tangential_abs = inf\n", "thresholds.tangential_abs", 17, 18,
                             "must be a finite number"));
    EXPECT_TRUE(single_error(std::string(kValid) + "[thresholds.box2d]\ntrajectory_rms = -0.08\n",
                             "thresholds.box2d.trajectory_rms", 17, 18, "must be >= 0"));
    // Every error of the tables is reported at once.
    const auto errors = errors_of(table + "bounce_count = 5.0\ntrajectory_max = -1\n[thresholds.bullet]\n"
                                          "trajectory_rms = -2\nspeed = 1\n");
    EXPECT_EQ(errors.size(), 4u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "thresholds.bounce_count", 17, 16, "expected an integer"));
    EXPECT_TRUE(has_error(errors, "thresholds.trajectory_max", 18, 18, "must be >= 0"));
    EXPECT_TRUE(has_error(errors, "thresholds.bullet.trajectory_rms", 20, 18, "must be >= 0"));
    EXPECT_TRUE(has_error(errors, "thresholds.bullet.speed", 21, 1, "unknown key"));
}

TEST(ScenarioLoaderInvalid, StringWhereNumberExpected) {
    EXPECT_TRUE(single_error(with("radius = 0.05", "radius = \"big\""), "ball.radius", 5, 10,
                             "expected a number, got a string"));
}

TEST(ScenarioLoaderInvalid, TableWhereArrayExpected) {
    EXPECT_TRUE(single_error(with("position = [0.5, 0.5, 0.5]", "position = {x = 0.5}"), "ball.position", 6, 12,
                             "expected an array of numbers, got a table"));
}

TEST(ScenarioLoaderInvalid, ArrayWhereTableExpected) {
    EXPECT_TRUE(single_error(with("[ball]", "[[ball]]"), "ball", 4, 1, "expected a table, got an array"));
    const std::string text = with("name = \"unit\"\n", "name = \"unit\"\nworld = [0.0, 0.0, -9.81]\n",
                                  with("[world]\ngravity = [0.0, 0.0, -9.81]\n", ""));
    EXPECT_TRUE(single_error(text, "world", 2, 9, "expected a table, got an array"));
}

TEST(ScenarioLoaderInvalid, NonNumberArrayElements) {
    const auto errors = errors_of(with("velocity = [0.3, 0.1, 0.2]", "velocity = [0.3, \"fast\", true]"));
    EXPECT_EQ(errors.size(), 2u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "ball.velocity[1]", 7, 18, "expected a number, got a string"));
    EXPECT_TRUE(has_error(errors, "ball.velocity[2]", 7, 26, "expected a number, got a boolean"));
    EXPECT_TRUE(single_error(with("size = [1.0, 1.0, 1.0]", "size = [1.0, [1.0], 1.0]"), "room.size[1]", 3, 14,
                             "got an array"));
}

TEST(ScenarioLoaderInvalid, NameNotAString) {
    EXPECT_TRUE(single_error(with("name = \"unit\"", "name = 42"), "name", 1, 8, "expected a string, got an integer"));
    EXPECT_TRUE(single_error(with("name = \"unit\"", "name = \"unit\"\ndescription = 1"), "description", 2, 15,
                             "expected a string"));
}

TEST(ScenarioLoaderInvalid, NameNotUsableAsFolderName) {
    EXPECT_TRUE(single_error(with("name = \"unit\"", "name = \"\""), "name", 1, 8, "must not be empty"));
    EXPECT_TRUE(single_error(with("name = \"unit\"", "name = \"a/b\""), "name", 1, 8, "not usable as a folder name"));
    EXPECT_TRUE(single_error(with("name = \"unit\"", "name = \"two words\""), "name", 1, 8, "only letters"));
    EXPECT_TRUE(single_error(with("name = \"unit\"", "name = \".hidden\""), "name", 1, 8, "must not start with '.'"));
    EXPECT_TRUE(single_error(with("name = \"unit\"", "name = \"..\""), "name", 1, 8, "must not start with '.'"));
    const std::string long_name = "name = \"" + std::string(300, 'a') + "\"";
    EXPECT_TRUE(single_error(with("name = \"unit\"", long_name), "name", 1, 8, "the limit is 255"));
}

TEST(ScenarioLoaderInvalid, RoomSizeOfWrongLength) {
    // With no usable dimension, the other vectors are only held to "2 or 3".
    EXPECT_TRUE(single_error(with("size = [1.0, 1.0, 1.0]", "size = [1.0, 1.0, 1.0, 1.0]"), "room.size", 3, 8,
                             "expected an array of 2 or 3 numbers, got 4 elements"));
    EXPECT_TRUE(single_error(with("size = [1.0, 1.0, 1.0]", "size = []"), "room.size", 3, 8, "got 0 elements"));
}

TEST(ScenarioLoaderInvalid, VectorLengthMismatchedWithRoom) {
    EXPECT_TRUE(single_error(with("position = [0.5, 0.5, 0.5]", "position = [0.5, 0.5]"), "ball.position", 6, 12,
                             "expected 3 numbers to match the dimension of room.size, got 2"));
    const auto errors = errors_of(with("size = [1.0, 1.0, 1.0]", "size = [1.0, 1.0]"));
    EXPECT_EQ(errors.size(), 3u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "ball.position", 6, 12, "expected 2 numbers"));
    EXPECT_TRUE(has_error(errors, "ball.velocity", 7, 12, "expected 2 numbers"));
    EXPECT_TRUE(has_error(errors, "world.gravity", 9, 11, "expected 2 numbers"));
}

TEST(ScenarioLoaderInvalid, NanAndInfRejected) {
    EXPECT_TRUE(single_error(with("radius = 0.05", "radius = nan"), "ball.radius", 5, 10,
                             "must be a finite number, got nan"));
    EXPECT_TRUE(single_error(with("gravity = [0.0, 0.0, -9.81]", "gravity = [0.0, 0.0, -inf]"), "world.gravity[2]", 9,
                             22, "must be a finite number, got -inf"));
    EXPECT_TRUE(single_error(with("duration = 1.0", "duration = +inf"), "run.duration", 15, 12, "finite"));
}

TEST(ScenarioLoaderInvalid, ExtremeMagnitudesRejected) {
    EXPECT_TRUE(single_error(with("velocity = [0.3, 0.1, 0.2]", "velocity = [1e300, 0.1, 0.2]"), "ball.velocity[0]",
                             7, 13, "exceeds the limit"));
    // Beyond 2^53 an integer would not survive the conversion to double.
    EXPECT_TRUE(single_error(with("duration = 1.0", "duration = 9007199254740993"), "run.duration", 15, 12,
                             "exceeds the limit"));
}

TEST(ScenarioLoaderInvalid, RadiusBelowOneNanometre) {
    // Box2D aborts on a ball of 1e-100 (2D), ODE on one of 1e-300: refused with the limit.
    std::string text = with("size = [1.0, 1.0, 1.0]", "size = [1e-299, 1e-299, 1e-299]");
    text = with("radius = 0.05", "radius = 1e-300", text);
    text = with("position = [0.5, 0.5, 0.5]", "position = [5e-300, 5e-300, 5e-300]", text);
    EXPECT_TRUE(single_error(text, "ball.radius", 5, 10, "1e-300 m is below the limit of 1e-09 m"));
    EXPECT_TRUE(single_error(with("radius = 0.05", "radius = 9.99e-10"), "ball.radius", 5, 10, "below the limit"));
    text = with("size = [1.0, 1.0, 1.0]", "size = [3e-9, 3e-9, 3e-9]");
    text = with("radius = 0.05", "radius = 1e-9", text);
    text = with("position = [0.5, 0.5, 0.5]", "position = [1.5e-9, 1.5e-9, 1.5e-9]", text);
    EXPECT_EQ(parse_scenario(text, "nanometre.toml").radius, 1e-9);
}

TEST(ScenarioLoaderInvalid, RadiusNotPositive) {
    EXPECT_TRUE(single_error(with("radius = 0.05", "radius = 0.0"), "ball.radius", 5, 10, "must be > 0, got 0"));
    // A negative radius also makes the position check meaningless; only the radius is reported.
    EXPECT_TRUE(single_error(with("radius = 0.05", "radius = -0.05"), "ball.radius", 5, 10, "must be > 0"));
}

TEST(ScenarioLoaderInvalid, RoomSideNotLargerThanDiameter) {
    // 0.1 == 2 x 0.05 exactly: the ball would touch both walls, which is rejected.
    EXPECT_TRUE(single_error(with("size = [1.0, 1.0, 1.0]", "size = [1.0, 0.1, 1.0]"), "room.size[1]", 3, 14,
                             "must be larger than the ball's diameter 2 x radius = 0.1"));
    EXPECT_TRUE(has_error(errors_of(with("size = [1.0, 1.0, 1.0]", "size = [1.0, 1.0, -2.0]")), "room.size[2]", 3, 19,
                          "diameter"));
}

TEST(ScenarioLoaderInvalid, BallStartsOutsideRoom) {
    EXPECT_TRUE(single_error(with("position = [0.5, 0.5, 0.5]", "position = [0.5, 0.5, 0.96]"), "ball.position[2]", 6,
                             23, "ball starts outside the room: centre z = 0.96 must be within"));
    EXPECT_TRUE(single_error(with("position = [0.5, 0.5, 0.5]", "position = [0.04, 0.5, 0.5]"), "ball.position[0]", 6,
                             13, "[0.05, 0.95]"));
    EXPECT_TRUE(single_error(with("position = [0.5, 0.5, 0.5]", "position = [0.5, -3, 0.5]"), "ball.position[1]", 6,
                             18, "centre y = -3"));
}

TEST(ScenarioLoaderInvalid, DtNotPositive) {
    EXPECT_TRUE(single_error(with("dt = 0.03", "dt = 0.0"), "run.dt", 14, 6, "must be > 0, got 0"));
    EXPECT_TRUE(single_error(with("dt = 0.03", "dt = -0.03"), "run.dt", 14, 6, "must be > 0"));
}

TEST(ScenarioLoaderInvalid, DurationNotPositive) {
    EXPECT_TRUE(single_error(with("duration = 1.0", "duration = 0"), "run.duration", 15, 12, "must be > 0, got 0"));
}

TEST(ScenarioLoaderInvalid, DtLargerThanDuration) {
    EXPECT_TRUE(single_error(with("dt = 0.03", "dt = 2.0"), "run.dt", 14, 6, "dt 2 is larger than duration 1"));
}

TEST(ScenarioLoaderInvalid, DampingOutsideUnitInterval) {
    EXPECT_TRUE(single_error(with("normal = 0.8", "normal = -0.1"), "damping.normal", 11, 10,
                             "must be within [0, 1], got -0.1"));
    EXPECT_TRUE(single_error(with("tangential = 0.99", "tangential = 1.01"), "damping.tangential", 12, 14,
                             "must be within [0, 1], got 1.01"));
}

TEST(ScenarioLoaderInvalid, TooManySteps) {
    const std::string text = with("dt = 0.03\nduration = 1.0", "dt = 1e-5\nduration = 1e8");
    EXPECT_TRUE(single_error(text, "run.dt", 14, 6, "duration / dt = 1e+13 steps exceeds the limit"));
}

TEST(ScenarioLoaderInvalid, SyntaxErrorHasParserLocation) {
    const auto errors = errors_of(with("radius = 0.05", "radius = = 0.05"));
    ASSERT_EQ(errors.size(), 1u) << dump(errors);
    EXPECT_EQ(errors[0].file, "test.toml");
    EXPECT_EQ(errors[0].line, 5);
    EXPECT_EQ(errors[0].column, 10);
    EXPECT_EQ(errors[0].key, "");
    EXPECT_FALSE(errors[0].reason.empty());
}

TEST(ScenarioLoaderInvalid, DuplicateKeyIsASyntaxError) {
    const auto errors = errors_of(with("dt = 0.03", "dt = 0.03\ndt = 0.04"));
    EXPECT_TRUE(has_error(errors, "", 15, 6, "cannot redefine"));
}

// --- The example files under tests/data/invalid --------------------------------

TEST(ScenarioLoaderInvalidFiles, SeveralErrorsAllReported) {
    const fs::path file = kInvalidDir / "several-errors.toml";
    std::vector<Diagnostic> errors;
    try {
        load_scenario(file);
        ADD_FAILURE() << "accepted " << file;
    } catch (const ScenarioError& e) {
        errors = e.diagnostics();
        // what() lists every diagnostic, one per line, in file order.
        std::string expected;
        for (const Diagnostic& d : errors) {
            if (!expected.empty()) expected += '\n';
            expected += d.format();
        }
        EXPECT_EQ(e.what(), expected);
    }
    ASSERT_EQ(errors.size(), 7u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "name", 2, 8, "not usable as a folder name"));
    EXPECT_TRUE(has_error(errors, "colour", 3, 1, "unknown key"));
    EXPECT_TRUE(has_error(errors, "ball.radius", 9, 10, "expected a number, got a string"));
    EXPECT_TRUE(has_error(errors, "ball.position", 10, 12, "expected 2 numbers"));
    EXPECT_TRUE(has_error(errors, "damping.tangential", 16, 1, "missing required key"));
    EXPECT_TRUE(has_error(errors, "damping.normal", 17, 10, "within [0, 1]"));
    EXPECT_TRUE(has_error(errors, "run.duration", 21, 12, "must be > 0"));
    for (const Diagnostic& d : errors) EXPECT_EQ(d.file, file.string());
    EXPECT_TRUE(std::is_sorted(errors.begin(), errors.end(),
                               [](const Diagnostic& a, const Diagnostic& b) { return a.line < b.line; }));
}

TEST(ScenarioLoaderInvalidFiles, SyntaxError) {
    const fs::path file = kInvalidDir / "syntax-error.toml";
    const auto errors = load_errors_of(file);
    ASSERT_EQ(errors.size(), 1u) << dump(errors);
    // The unclosed array on line 4 is noticed where the next table starts.
    EXPECT_TRUE(has_error(errors, "", 6, 1, "array"));
    EXPECT_EQ(errors[0].format().rfind(file.string() + ":6:1: ", 0), 0u) << errors[0].format();
}

TEST(ScenarioLoaderInvalidFiles, OutsideRoom2D) {
    const auto errors = load_errors_of(kInvalidDir / "outside-room.toml");
    ASSERT_EQ(errors.size(), 1u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "ball.position[1]", 9, 18, "centre y = 0.97 must be within [radius, size - radius]"));
}

TEST(ScenarioLoaderInvalidFiles, ReservedTables) {
    const auto errors = load_errors_of(kInvalidDir / "reserved-tables.toml");
    ASSERT_EQ(errors.size(), 2u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "engines.box2d.enabled", 24, 1, "unknown key"));
    EXPECT_TRUE(has_error(errors, "thresholds.bounce_count", 27, 16, "expected an integer, got a floating-point number"));
}

TEST(ScenarioLoaderInvalidFiles, Thresholds) {
    const auto errors = load_errors_of(kInvalidDir / "thresholds.toml");
    ASSERT_EQ(errors.size(), 6u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "thresholds.bounce_count", 25, 16, "must be within [1, 10000], got 0"));
    EXPECT_TRUE(has_error(errors, "thresholds.trajectory_max", 26, 18, "must be >= 0, got -0.2"));
    EXPECT_TRUE(has_error(errors, "thresholds.ode", 27, 7, "expected a table, got an integer"));
    EXPECT_TRUE(has_error(errors, "thresholds.bullet.trajectory_rms", 30, 18, "expected a number, got a string"));
    EXPECT_TRUE(has_error(errors, "thresholds.bullet.tolerance", 31, 1, "unknown key"));
    EXPECT_TRUE(has_error(errors, "thresholds.warpdrive", 33, 13, "unknown simulator"));
}

TEST(ScenarioLoaderInvalidFiles, NonFinite) {
    const auto errors = load_errors_of(kInvalidDir / "non-finite.toml");
    ASSERT_EQ(errors.size(), 4u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "room.size[0]", 5, 9, "got inf"));
    EXPECT_TRUE(has_error(errors, "ball.velocity[0]", 10, 13, "got nan"));
    EXPECT_TRUE(has_error(errors, "world.gravity[1]", 13, 17, "got -inf"));
    EXPECT_TRUE(has_error(errors, "run.duration", 21, 12, "got inf"));
}

TEST(ScenarioLoaderInvalidFiles, MismatchedDimensions) {
    const auto errors = load_errors_of(kInvalidDir / "mismatched-dimensions.toml");
    ASSERT_EQ(errors.size(), 2u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "ball.position", 9, 12, "expected 2 numbers"));
    EXPECT_TRUE(has_error(errors, "ball.velocity", 10, 12, "got 1"));
}

TEST(ScenarioLoaderInvalidFiles, MissingTables) {
    const auto errors = load_errors_of(kInvalidDir / "missing-tables.toml");
    ASSERT_EQ(errors.size(), 5u) << dump(errors);
    for (const char* table : {"room", "ball", "world", "damping", "run"})
        EXPECT_TRUE(has_error(errors, table, 1, 1, "missing required table"));
}

// Every example file is rejected with located diagnostics naming the file.
TEST(ScenarioLoaderInvalidFiles, EveryExampleIsRejected) {
    int files = 0;
    for (const fs::directory_entry& entry : fs::directory_iterator(kInvalidDir)) {
        SCOPED_TRACE(entry.path().string());
        const auto errors = load_errors_of(entry.path());
        EXPECT_FALSE(errors.empty());
        for (const Diagnostic& d : errors) {
            EXPECT_EQ(d.file, entry.path().string());
            EXPECT_GE(d.line, 1);
            EXPECT_GE(d.column, 1);
            EXPECT_FALSE(d.reason.empty());
        }
        ++files;
    }
    EXPECT_GE(files, 10);
}

// --- Files ----------------------------------------------------------------------

TEST_F(ScenarioLoaderFiles, LoadsAFileAndRecordsItsPath) {
    const fs::path& file = write(kValid);
    EXPECT_EQ(load_scenario(file).source, file);
}

TEST_F(ScenarioLoaderFiles, MissingFile) {
    const fs::path file = dir_ / "no-such-scenario.toml";
    const auto errors = load_errors_of(file);
    ASSERT_EQ(errors.size(), 1u) << dump(errors);
    EXPECT_EQ(errors[0].file, file.string());
    EXPECT_EQ(errors[0].line, 0);
    EXPECT_EQ(errors[0].key, "");
    EXPECT_EQ(errors[0].format(), file.string() + ": cannot open: no such file");
}

TEST_F(ScenarioLoaderFiles, DirectoryInsteadOfFile) {
    const auto errors = load_errors_of(dir_);
    ASSERT_EQ(errors.size(), 1u) << dump(errors);
    EXPECT_NE(errors[0].reason.find("is a directory"), std::string::npos) << errors[0].reason;
}

TEST_F(ScenarioLoaderFiles, NotARegularFile) {
    // A device or FIFO could block or never end: refused before reading.
    if (!fs::exists("/dev/zero")) GTEST_SKIP() << "no /dev/zero";
    const auto errors = load_errors_of("/dev/zero");
    ASSERT_EQ(errors.size(), 1u) << dump(errors);
    EXPECT_NE(errors[0].reason.find("not a regular file"), std::string::npos) << errors[0].reason;
}

TEST_F(ScenarioLoaderFiles, UnreadableFile) {
    const fs::path& file = write(kValid);
    fs::permissions(file, fs::perms::none);
    if (std::ifstream(file).is_open()) GTEST_SKIP() << "permissions are not enforced for this user (root?)";
    const auto errors = load_errors_of(file);
    ASSERT_EQ(errors.size(), 1u) << dump(errors);
    EXPECT_NE(errors[0].reason.find("cannot open"), std::string::npos) << errors[0].reason;
}

TEST_F(ScenarioLoaderFiles, OversizedFile) {
    const fs::path& file = write(std::string(kValid) + "#" + std::string(2 << 20, 'x') + "\n");
    const auto errors = load_errors_of(file);
    ASSERT_EQ(errors.size(), 1u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "", 1, 1,
                          "file is " + std::to_string(fs::file_size(file)) + " bytes, larger than the limit"));
    // Just past the limit is too large, at the limit is read (and parsed).
    const std::string padded = std::string(kValid) + "#";
    fs::resize_file(file, (1u << 20) + 1);
    EXPECT_TRUE(has_error(load_errors_of(file), "", 1, 1, "1048577 bytes, larger than the limit"));
    std::ofstream(file, std::ios::binary) << padded << std::string((1u << 20) - padded.size() - 1, 'x') << "\n";
    ASSERT_EQ(fs::file_size(file), 1u << 20);
    EXPECT_EQ(load_scenario(file).name, "unit");
}

// --- Hostile input: only ScenarioError, never a crash or a hang ---------------------

TEST(ScenarioLoaderRobustness, EmptyInput) {
    const auto errors = errors_of("");
    ASSERT_EQ(errors.size(), 6u) << dump(errors);
    EXPECT_TRUE(has_error(errors, "name", 1, 1, "missing required key"));
    EXPECT_TRUE(has_error(errors, "run", 1, 1, "missing required table"));
}

TEST(ScenarioLoaderRobustness, BinaryGarbage) {
    using namespace std::string_literals;
    const std::vector<std::string> garbage = {
        "\x00"s,
        "\xff\xfe\x00\x00"s,
        "\xef\xbb\xbf"s,  // a byte order mark and nothing else
        "\x7f\x45\x4c\x46\x02\x01\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x03\x00\x3e\x00"s,  // an ELF header
        "name = \"a\x00b\"\n"s,
        "\xc3\x28 = 1\n[\xed\xa0\x80]\n"s,  // invalid UTF-8, an encoded surrogate
        "[[[[\n]]]]\n\"\"\"\n'''\n\\u0000\n"s,
        std::string(kValid).replace(20, 1, "\x00"s),
    };
    for (const std::string& bytes : garbage) {
        SCOPED_TRACE(::testing::PrintToString(bytes));
        EXPECT_THROW(parse_scenario(bytes, "garbage.toml"), ScenarioError);
    }
}

TEST(ScenarioLoaderRobustness, RandomBytesAndMutations) {
    // Deterministic fuzzing: random buffers, and the valid text with bytes
    // overwritten. Each input either loads or throws ScenarioError.
    std::mt19937 rng(20240611);
    std::uniform_int_distribution<int> byte(0, 255);
    const std::string alphabet = "[]{}=.,\"'#\n 0123456789einfa-+_xyz\\";
    std::uniform_int_distribution<std::size_t> pick(0, alphabet.size() - 1);
    for (int round = 0; round < 600; ++round) {
        std::string input;
        if (round % 2 == 0) {
            input.resize(static_cast<std::size_t>(byte(rng)));
            for (char& c : input) c = static_cast<char>(round % 4 == 0 ? byte(rng) : alphabet[pick(rng)]);
        } else {
            input = kValid;
            std::uniform_int_distribution<std::size_t> where(0, input.size() - 1);
            for (int edits = 1 + round % 3; edits > 0; --edits) input[where(rng)] = alphabet[pick(rng)];
        }
        SCOPED_TRACE(::testing::PrintToString(input));
        try {
            parse_scenario(input, "fuzz.toml");
        } catch (const ScenarioError& e) {
            EXPECT_FALSE(e.diagnostics().empty());
            for (const Diagnostic& d : e.diagnostics()) EXPECT_EQ(d.format().find('\n'), std::string::npos);
        }
    }
}

TEST(ScenarioLoaderRobustness, DeeplyNestedTables) {
    // toml++ would overflow the stack on these; the loader refuses them first.
    std::string header = "[a";
    for (int i = 0; i < 100000; ++i) header += ".a";
    header += "]\n";
    EXPECT_TRUE(single_error(header, "", 1, 2003, "refusing keys nested this deeply"));
    std::string dotted = "a";
    for (int i = 0; i < 100000; ++i) dotted += ".a";
    EXPECT_TRUE(single_error(dotted + " = 1\n", "", 1, 2002, "nested"));
    // Nested arrays and inline tables are bounded by the parser itself.
    EXPECT_THROW(parse_scenario("x = " + std::string(5000, '[') + std::string(5000, ']'), "deep.toml"),
                 ScenarioError);
    EXPECT_THROW(parse_scenario("x = " + std::string(5000, '{') , "deep.toml"), ScenarioError);
}

TEST(ScenarioLoaderRobustness, DotsInStringsAndCommentsAreNotNesting) {
    const std::string dots(5000, '.');
    std::string text = with("name = \"unit\"\n", "name = \"unit\"\ndescription = \"\"\"\"" + dots + "\\\"\"\"\"\" # " +
                                                     dots + "\n");
    text = with("[room]\n", "[room] # " + dots + "\n", text);
    EXPECT_EQ(parse_scenario(text, "dots.toml").description, "\"" + dots + "\"\"");
    text = with("name = \"unit\"\n", "name = \"unit\"\ndescription = '''" + dots + "'''\n");
    EXPECT_EQ(parse_scenario(text, "dots.toml").description, dots);
}

TEST(ScenarioLoaderRobustness, NonAsciiOnlyInStringsAndComments) {
    const std::string text = with("name = \"unit\"\n", "name = \"unit\" # café\ndescription = \"Über café, 1 m³\"\n");
    EXPECT_EQ(parse_scenario(text, "unicode.toml").description, "Über café, 1 m³");
    // TOML allows none elsewhere, and toml++ 3.3 has undefined behaviour on some.
    EXPECT_TRUE(single_error(with("radius = 0.05", "radius = 0.05§"), "", 5, 14,
                             "non-ASCII character outside a string or comment"));
    // A quote inside a bare value is no string to toml++: found by parsing an ASCII stand-in first.
    EXPECT_TRUE(single_error(with("radius = 0.05", "radius = 0\"§\""), "", 5, kAnyColumn, "parsing"));
    // Valid TOML that toml++ 3.3 cannot parse safely (marzer/tomlplusplus#190): refused with a reason.
    EXPECT_TRUE(single_error(with("name = \"unit\"\n", "name = \"unit\"\ndescription = \"\"\"a \\\n  § b\"\"\"\n"), "",
                             3, 3, "after a backslash in a multi-line string"));
}

TEST(ScenarioLoaderRobustness, Utf8) {
    EXPECT_EQ(parse_scenario("\xEF\xBB\xBF" + std::string(kValid), "bom.toml").name, "unit");  // byte order mark
    EXPECT_TRUE(single_error(with("name = \"unit\"", "name = \"un\xFF\""), "", 1, 11, "invalid UTF-8"));
    // An encoded surrogate, an overlong '/', a truncated sequence.
    for (const char* bad : {"\xED\xA0\x80", "\xC0\xAF", "\xE2\x82"}) {
        EXPECT_TRUE(single_error(with("name = \"unit\"", std::string("name = \"") + bad + "\""), "", 1, 9,
                                 "invalid UTF-8"));
    }
}

TEST(ScenarioLoaderRobustness, EveryDiagnosticIsOneLine) {
    // toml++ quotes the raw input in some messages, here a newline.
    const auto errors = errors_of(with("radius = 0.05", "radius = -in"));
    ASSERT_EQ(errors.size(), 1u) << dump(errors);
    EXPECT_NE(errors[0].reason.find("\\u000A"), std::string::npos) << errors[0].reason;
    EXPECT_EQ(errors[0].format().find('\n'), std::string::npos) << errors[0].format();
}

TEST(ScenarioLoaderRobustness, HugeNumbers) {
    // Out of the range of double or int64: toml++ reports them as syntax errors.
    EXPECT_TRUE(single_error(with("radius = 0.05", "radius = 1e400"), "", 5, kAnyColumn, "1e400"));
    EXPECT_TRUE(single_error(with("radius = 0.05", "radius = 99999999999999999999"), "", 5, kAnyColumn, "64 bits"));
    EXPECT_TRUE(single_error(with("dt = 0.03\nduration = 1.0", "dt = 1e-9\nduration = 1e15"), "run.dt", 14, 6,
                             "1e+24 steps exceeds the limit"));
}

TEST(ScenarioLoaderInvalid, DtBelowOneNanosecond) {
    // ODE aborts on a subnormal dt, and on one of 1e-300 at speeds of 1e15.
    EXPECT_TRUE(single_error(with("dt = 0.03\nduration = 1.0", "dt = 5e-324\nduration = 1e-300"), "run.dt", 14, 6,
                             "5e-324 s is below the limit of 1e-09 s"));
    EXPECT_TRUE(single_error(with("dt = 0.03", "dt = 9.99e-10"), "run.dt", 14, 6, "below the limit"));
    EXPECT_EQ(parse_scenario(with("dt = 0.03", "dt = 1e-9"), "nanosecond.toml").dt, 1e-9);
    // Elsewhere subnormal numbers are just small numbers.
    const Scenario s = parse_scenario(with("velocity = [0.3, 0.1, 0.2]", "velocity = [0.3, 5e-324, 0]"), "tiny.toml");
    EXPECT_EQ(s.velocity.y(), std::numeric_limits<double>::denorm_min());
}

TEST(ScenarioLoaderRobustness, OversizedText) {
    EXPECT_TRUE(single_error(std::string(kValid) + std::string(2 << 20, ' '), "", 1, 1,
                             "input is larger than the limit of 1048576 bytes"));
}

// --- Formatting ---------------------------------------------------------------------

TEST(ScenarioLoaderDiagnostic, FormatOmitsMissingParts) {
    EXPECT_EQ((Diagnostic{"f.toml", 3, 7, "ball.radius", "must be > 0"}.format()),
              "f.toml:3:7: ball.radius: must be > 0");
    EXPECT_EQ((Diagnostic{"f.toml", 3, 7, "", "syntax"}.format()), "f.toml:3:7: syntax");
    EXPECT_EQ((Diagnostic{"f.toml", 3, 0, "k", "r"}.format()), "f.toml:3: k: r");
    EXPECT_EQ((Diagnostic{"f.toml", 0, 0, "", "cannot open"}.format()), "f.toml: cannot open");
    EXPECT_EQ((Diagnostic{"", 3, 7, "k", "r"}.format()), "3:7: k: r");
    EXPECT_EQ((Diagnostic{"", 0, 0, "", "r"}.format()), "r");
}

TEST(ScenarioLoaderDiagnostic, ErrorListsAllDiagnostics) {
    const ScenarioError error({{"a.toml", 1, 2, "x", "first"}, {"a.toml", 3, 4, "y", "second"}});
    EXPECT_STREQ(error.what(), "a.toml:1:2: x: first\na.toml:3:4: y: second");
    EXPECT_EQ(error.diagnostics().size(), 2u);
}

}  // namespace
}  // namespace bouncecheck
