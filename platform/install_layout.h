// Where bouncecheck finds what it ships beside its binary: the engines'
// modules and the bundled scenarios. Found from the binary's own location,
// so that an installed copy (`cmake --install`, the Debian package) works
// wherever its prefix is, and the build tree works as built:
//
//   PREFIX/bin/bouncecheck
//   PREFIX/lib/bouncecheck/engines/bouncecheck-engine-<folder>.so
//   PREFIX/share/bouncecheck/scenarios/*.toml
//   PREFIX/lib/bouncecheck/node/<name>.mjs, host/, node_modules/
//
//   build/bouncecheck, build/engines/*.so, and the source's scenarios/ and
//   engines/node/.
#pragma once

#include <filesystem>

namespace bouncecheck {

// Relative to the binary's folder: the layout `cmake --install` writes.
inline constexpr const char* kInstalledEngineDir = "../lib/bouncecheck/engines";
inline constexpr const char* kInstalledScenarioDir = "../share/bouncecheck/scenarios";
inline constexpr const char* kInstalledNodeEngineDir = "../lib/bouncecheck/node";

// The folder of the running program (/proc/self/exe, links resolved); empty
// if the kernel does not say.
std::filesystem::path executable_dir();

// The engines' modules: the installed layout beside the binary if it is
// there, else the build tree's folder beside the binary (build/engines/),
// else the folder this build wrote them to (for the build's own test and
// benchmark programs, which live in sub-folders of the build).
std::filesystem::path engine_module_dir();

// The Node-hosted engines' files (engines/node/: one per engine, the shared
// host, the npm packages): the installed layout beside the binary if it is
// there, else the source tree's.
std::filesystem::path node_engine_dir();

// The bundled scenarios: $BOUNCECHECK_SCENARIOS if set, else the installed
// layout beside the binary if it is there, else the source tree's.
std::filesystem::path bundled_scenario_dir();

}  // namespace bouncecheck
