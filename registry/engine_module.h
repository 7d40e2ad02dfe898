// An engine adapter as the registry holds it: what the engine is (its
// EngineIdentity, from the adapter's header) at once, the adapter itself only
// when a run needs it. Each adapter is built as a module of its own
// (build/engines/bouncecheck-engine-<folder>.so, linked against its engine's
// libraries), loaded the first time the engine is asked whether it can run a
// scenario: a command that runs no engine loads none of their libraries,
// which took most of a short run's time (DART and FCL alone resolve about
// 71,000 relocations at load).
#pragma once

#include "engines/engine.h"
#include "simulators/simulator.h"

#include <filesystem>
#include <memory>
#include <string_view>

namespace bouncecheck {

// The engine `identity` whose adapter is in engines/`folder`/: its module is
// bouncecheck-engine-<folder>.so in the build's engine folder, and the
// module's extern "C" function bouncecheck_engine_<name> (a '-' in the name
// as '_') makes it. If the module cannot be loaded, or has no such entry,
// the engine cannot run anything, and says why.
std::unique_ptr<const Simulator> engine_in_module(const EngineIdentity& identity, std::string_view folder);
// The module file of the adapter in engines/`folder`/, where it is looked for.
std::filesystem::path engine_module_file(std::string_view folder);

}  // namespace bouncecheck
