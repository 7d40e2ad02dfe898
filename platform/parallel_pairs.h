// The parallel schedule the sweep and the stress suite share: every
// (simulator, item) pair in a pool of long-lived worker processes, forked from
// this one, so that
// - every engine runs in parallel: processes share no library state, so even
//   engines with global state (ODE, Box2D, Siconos, DART) run side by side;
// - a pair that crashes the process (an engine's abort or assert) costs that
//   pair only: its worker is replaced;
// - a pair that hangs, even inside one engine step, is killed by a watchdog.
#pragma once

#include "platform/shard.h"

#include <cstddef>
#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bouncecheck {

// What became of one pair.
struct PairOutcome {
    enum class Kind { ok, crashed, hung };
    Kind kind = Kind::ok;
    std::string payload;  // ok: the bytes the pair's `run` returned
    // crashed or hung: why ("signal 6 (Aborted)", "no result after ...", an
    // exception's message), with the last lines the worker wrote to stderr.
    std::string failure;
};

// Why a finished pair has no result: its worker crashed or hung
// (PairOutcome::failure), or sent bytes the caller could not decode.
struct PairFailure {
    enum class Kind { crashed, hung, unreadable };
    Kind kind = Kind::crashed;
    std::string reason;
    // For a row's reason: "crashed: ...", "hung: ...", or the unreadable
    // result's reason as it is.
    std::string labelled() const {
        switch (kind) {
            case Kind::crashed: return "crashed: " + reason;
            case Kind::hung: return "hung: " + reason;
            case Kind::unreadable: break;
        }
        return reason;
    }
};

// Runs `decode(payload)` on a pair that ended ok; otherwise, or when
// `decode` throws, says why there is no result. The one way every
// `finished` handler reads a pair.
template <class Decode>
std::optional<PairFailure> decode_pair(const PairOutcome& ended, Decode&& decode) {
    if (ended.kind != PairOutcome::Kind::ok)
        return PairFailure{ended.kind == PairOutcome::Kind::hung ? PairFailure::Kind::hung : PairFailure::Kind::crashed,
                           ended.failure};
    try {
        decode(ended.payload);
        return std::nullopt;
    } catch (const std::exception& e) {
        return PairFailure{PairFailure::Kind::unreadable,
                           std::string("its worker process sent an unreadable result: ") + e.what()};
    }
}

struct PairSchedule {
    int jobs = 0;  // worker processes; 0: one per core
    // Relative cost of a pair (e.g. its steps x the simulator's typical cost
    // of one): the costliest pairs start first, so that no long pair starts
    // last and keeps one worker busy after the others are done.
    std::function<double(std::size_t simulator, std::size_t item)> cost;
    // The part of the pairs this process runs (`--shard K/N`): the pairs that
    // assign_shards gives shard K by the costs above. Default: all of them.
    Shard shard;
    // Wall time after which a pair is killed with its worker and reported
    // hung (s); 0: no limit.
    double deadline_seconds = 0;
    // Runs one pair, in a worker process, and returns its result as bytes. An
    // exception is a crashed pair with its message.
    std::function<std::string(std::size_t simulator, std::size_t item)> run;
    // In this process, as each pair ends, in the order they end: what became
    // of it, and `done` pairs ended so far of the `total` this process runs.
    std::function<void(std::size_t simulator, std::size_t item, const PairOutcome& outcome, std::size_t done,
                       std::size_t total)>
        finished;
};

// A shard's part of a run's per-pair results: the entries whose pair ran
// (`ran`, by slot), in slot order, and their slots.
template <class Result>
void keep_pairs_that_ran(const std::vector<bool>& ran, std::vector<Result>& results, std::vector<std::size_t>& slots) {
    std::vector<Result> kept;
    slots.clear();
    for (std::size_t slot = 0; slot < ran.size(); ++slot) {
        if (!ran[slot]) continue;
        kept.push_back(std::move(results[slot]));
        slots.push_back(slot);
    }
    results = std::move(kept);
}

// Runs every pair of [0, simulators) x [0, items) (of the schedule's shard), costliest first, one pair
// at a time per worker; min(jobs, pairs) workers are started once, not per
// pair (a fork costs about 3 ms), and replaced when one dies or is killed.
void run_pairs_in_parallel(std::size_t simulators, std::size_t items, const PairSchedule& schedule);

}  // namespace bouncecheck
