// Writes a scenario back as a scenario file (the stress suite's generated
// scenarios, kept for `bouncecheck run` to reproduce).
#pragma once

#include "scenarios/scenario.h"

#include <string>

namespace bouncecheck {

// Scenario text that load_scenario reads back to the same scenario (numbers
// with 17 significant digits; engine tables and thresholds left out).
std::string scenario_toml(const Scenario& s);

}  // namespace bouncecheck
