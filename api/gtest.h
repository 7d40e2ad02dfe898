// bouncecheck's GoogleTest helper (docs/library.md), installed as
// <bouncecheck/gtest.h>: one call asserts that a simulator follows the law
// on a scenario, for an engine's own test suite.
//
//   TEST(MyEngine, FollowsTheLaw) {
//       const bouncecheck::Scenario s = bouncecheck::load_scenario("seed-2d.toml");
//       EXPECT_FOLLOWS_THE_LAW(s, my_simulator);
//   }
//
// On failure the message names each check that failed, then shows the
// harness's table for the scenario.
#pragma once

#include "bouncecheck.h"

#include <gtest/gtest.h>

#include <string>

namespace bouncecheck::testing {

inline ::testing::AssertionResult FollowsTheLaw(const Scenario& s, const Simulator& sim,
                                                const LawTolerances& t = {}) {
    const LawCheck c = check_law(s, sim, t);
    if (c.passed) return ::testing::AssertionSuccess();
    ::testing::AssertionResult failure = ::testing::AssertionFailure();
    failure << std::string(sim.name()) << " does not follow the law on " << s.name << ":\n";
    for (const std::string& why : c.failures) failure << "  " << why << "\n";
    return failure << c.table;
}

}  // namespace bouncecheck::testing

#define EXPECT_FOLLOWS_THE_LAW(scenario, simulator, ...) \
    EXPECT_TRUE(::bouncecheck::testing::FollowsTheLaw(scenario, simulator, ##__VA_ARGS__))
#define ASSERT_FOLLOWS_THE_LAW(scenario, simulator, ...) \
    ASSERT_TRUE(::bouncecheck::testing::FollowsTheLaw(scenario, simulator, ##__VA_ARGS__))
