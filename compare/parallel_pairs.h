// The parallel schedule the sweep and the stress suite share: every
// (simulator, item) pair on oneTBB's threads, with the engines whose library
// keeps unsynchronised global state kept to one pair at a time.
#pragma once

#include "adapters/simulator.h"

#include <cstddef>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

namespace bouncecheck {

// Engines whose pairs run one after another, never alongside each other
// (a shared library state that is not safe across threads), with the reason.
std::optional<std::string_view> serial_engine_reason(std::string_view engine);

struct PairSchedule {
    int jobs = 0;  // worker threads; 0: every core
    // Relative cost of an item (e.g. its step count): the costliest pairs start first.
    std::function<double(std::size_t item)> cost;
    // Runs one pair; called from a worker thread, each pair exactly once.
    std::function<void(std::size_t simulator, std::size_t item)> run;
    // After each pair, under a lock: `done` pairs finished so far.
    std::function<void(std::size_t simulator, std::size_t item, std::size_t done)> finished;
};

// Runs every pair of simulators x [0, items). A serial engine's pairs form
// one task, in item order; every other pair is a task of its own, costliest
// first; one task per TBB chunk, so a long task never holds up others.
void run_pairs_in_parallel(const std::vector<const Simulator*>& simulators, std::size_t items,
                           const PairSchedule& schedule);

}  // namespace bouncecheck
