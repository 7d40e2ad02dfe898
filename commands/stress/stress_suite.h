// The stress suite's scenarios: the bundled files under scenarios/stress/,
// and two families generated in code (wall starts, a Monte-Carlo set), the
// same on every build.
#pragma once

#include "reports/stress_report.h"
#include "scenarios/scenario.h"

#include <cstdint>
#include <functional>
#include <string>
#include <random>
#include <vector>

namespace bouncecheck {

// Uniform double in [0, 1) from the top 53 bits of one draw. The suite's
// random numbers use only this and integer arithmetic on the engine's output,
// whose sequence the C++ standard fixes, so every build generates the same set.
double unit_draw(std::mt19937_64& g);

// `count` random valid scenarios (they pass the loader's validation) from
// `seed`, drawn one after another from one generator: scenario n depends on
// the seed and n only, so a larger count extends a smaller one's set: 2D or 3D, room sides 0.2-3 m, radius 0.5-20% of the smallest side,
// speeds up to 2 m/s per axis, gravity up to 10 m/s^2 (sometimes none,
// sometimes tilted), alpha and beta over [0, 1] with 0 and 1 themselves
// frequent, starts touching walls, dt from 2.4e-4 to 0.0625 s, 200-2000 steps.
// With `keep`, only the scenarios whose name it keeps are made and held:
// each is still drawn in turn, so memory stays that of the kept ones.
std::vector<Scenario> monte_carlo_scenarios(std::uint64_t seed, int count,
                                            const std::function<bool(const std::string& name)>& keep = {});

// A ball starting in contact with each wall of a 2D and a 3D room, moving
// into it, away from it, and at rest: 30 scenarios.
std::vector<Scenario> wall_start_scenarios();

// Which of the suite's cases to keep, by row and scenario name (`--only`).
using StressCaseFilter = std::function<bool(const std::string& row, const std::string& name)>;

// The whole suite: the given files' scenarios (one row each), then the
// wall-start and Monte-Carlo families; with `keep`, only the cases it keeps.
std::vector<StressCase> stress_suite(const std::vector<Scenario>& files, const MonteCarloSet& monte_carlo = {},
                                     const StressCaseFilter& keep = {});

}  // namespace bouncecheck
