// The parallel schedule the sweep and the stress suite share: every
// (simulator, item) pair on oneTBB's threads, with the simulators that must
// not run alongside themselves (Simulator::serial_reason) kept to one pair at
// a time.
#pragma once

#include <cstddef>
#include <functional>

namespace bouncecheck {

struct PairSchedule {
    int jobs = 0;  // worker threads; 0: every core
    // Relative cost of an item (e.g. its step count): the costliest pairs start first.
    std::function<double(std::size_t item)> cost;
    // Whether a simulator's pairs must run one after another, never alongside
    // each other (a library state that is not safe across threads).
    std::function<bool(std::size_t simulator)> serial;
    // Runs one pair; called from a worker thread, each pair exactly once.
    std::function<void(std::size_t simulator, std::size_t item)> run;
    // After each pair, under a lock: `done` pairs finished so far.
    std::function<void(std::size_t simulator, std::size_t item, std::size_t done)> finished;
};

// Runs every pair of [0, simulators) x [0, items). A serial simulator's pairs
// form one task, in item order; every other pair is a task of its own,
// costliest first; one task per TBB chunk, so a long task never holds up others.
void run_pairs_in_parallel(std::size_t simulators, std::size_t items, const PairSchedule& schedule);

}  // namespace bouncecheck
