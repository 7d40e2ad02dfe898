// What this build contains: every simulator, `reference` and `exact` first,
// then each engine whose CMake option was on.
#pragma once

#include "simulators/simulator.h"

#include <memory>
#include <vector>

namespace bouncecheck {

std::vector<std::unique_ptr<const Simulator>> built_simulators();

}  // namespace bouncecheck
