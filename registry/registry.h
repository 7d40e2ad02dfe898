// What this build contains: every simulator, `reference` and `exact` first,
// then each engine whose CMake option was on.
#pragma once

#include "external/external_simulator.h"
#include "simulators/simulator.h"

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace bouncecheck {

// `hosted`: how long an engine run as a program of its own (the Node-hosted
// ones) may go silent and run in all: the command's --external-timeout and
// --budget, as for an external program.
std::vector<std::unique_ptr<const Simulator>> built_simulators(ExternalLimits hosted = {});

// Where each engine's module is loaded from (platform/install_layout.h), in
// built_simulators' order; the file may be missing (then the engine says so).
struct EngineModule {
    std::string simulator;
    std::filesystem::path file;
};
std::vector<EngineModule> engine_modules();

}  // namespace bouncecheck
