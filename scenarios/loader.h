// Loading and validating scenario files (TOML; see scenarios/seed-3d.toml).
//
// Every problem of a file is collected and reported at once, each located by
// file, line, column and dotted key, before anything runs. Nothing but
// ScenarioError escapes, whatever the input.
#pragma once

#include "scenarios/scenario.h"

#include <array>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

// One located problem.
struct Diagnostic {
    std::string file;          // path as given
    int line = 0, column = 0;  // 1-based; 0 if unknown
    std::string key;           // dotted key path, empty for syntax/file errors
    std::string reason;

    // "FILE:LINE:COLUMN: KEY: REASON", leaving out the parts that are empty or 0.
    std::string format() const;
};

// what() is every diagnostic formatted, one per line.
class ScenarioError : public std::runtime_error {
public:
    explicit ScenarioError(std::vector<Diagnostic> d);
    const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

private:
    std::vector<Diagnostic> diagnostics_;
};

// Limits of a valid run, also applied to the dts a sweep is given: below 1e-9 s
// a step makes ODE abort at extreme speeds (see loader.cpp). Up to 1e12
// steps the document's clock still moves by about dt at every step; the
// reference and exact hand their rest over in closed form, so such a run costs
// what its motion before rest costs, but an engine steps every one (days:
// give `run` a --budget).
inline constexpr double kMinDt = 1e-9;
inline constexpr double kMaxSteps = 1e12;

// Every simulator bouncecheck can be built with (built or not, so that a
// file validates the same on every build): a scenario's [thresholds.<name>]
// may name one, and an external simulator may not take one's name. The
// engines are all of them but the first two.
inline constexpr std::array<std::string_view, 23> kBuiltInSimulators{
    "reference", "exact",  "bullet", "ode",   "box2d",  "mujoco",  "chipmunk", "siconos", "siconos-ed", "dart",
    "rapier",    "jolt",   "physx",  "havok", "box2d3", "mujoco3", "planck",   "p2",      "oimo",       "cannon",
    "ammo",      "matter", "box2d-wasm"};
std::span<const std::string_view> built_in_engines();

// The engines hosted by Node (engines/node/<name>.mjs, docs/engines.md):
// their [engines.<name>] tables may hold, besides the shared keys, the
// engine's own (each a string, number or boolean, or a flat array of them),
// passed on as written;
// the engine's file refuses a value it cannot use. Empty for any other engine.
std::span<const std::string_view> hosted_engine_keys(std::string_view engine);
bool is_hosted_engine(std::string_view engine);

// Why `name` cannot name a scenario or an external simulator (it becomes a
// folder or a file name): nothing if it can.
std::optional<std::string> name_problem(std::string_view name);

// Reads and validates a scenario file. `external_names`: the external
// simulators declared outside the file (--external), whose [engines.<name>]
// and [thresholds.<name>] tables the file may hold besides those of its own
// [external.<name>]. Throws ScenarioError.
Scenario load_scenario(const std::filesystem::path& file, const std::vector<std::string>& external_names = {});

// Validates scenario text; `file_name` is used in diagnostics, as
// Scenario::source, and as the base of a relative external program. Throws
// ScenarioError. For tests and fuzzing.
Scenario parse_scenario(std::string_view toml_text, const std::string& file_name,
                        const std::vector<std::string>& external_names = {});

}  // namespace bouncecheck
