// One of N parts of a run's pairs (`--shard K/N`), for a run spread over the
// tasks of a cluster job array (scripts/slurm/): each shard runs its pairs
// and `bouncecheck merge` puts the parts back together.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

struct Shard {
    int index = 1;  // 1..count
    int count = 1;
    bool whole() const { return count == 1; }
};

// "K/N" with 1 <= K <= N <= kMaxShards; nothing, and `error` says why, otherwise.
inline constexpr int kMaxShards = 1'000'000;
std::optional<Shard> parse_shard(std::string_view text, std::string& error);
std::string to_string(const Shard& s);

// The shard (1..count) of each pair, given the pairs' costs in a fixed order:
// longest processing time first. The pairs go costliest first (equal costs:
// the earlier pair first), each to the shard with the least cost so far
// (equal: the lower shard). The costs are estimates from the scenario and the
// simulator alone (steps x typical ns per step), never measured, so every
// machine computes the same assignment, and the costliest pairs spread across
// the shards. With n pairs, no shard's cost exceeds the mean by more than the
// costliest pair's.
std::vector<int> assign_shards(const std::vector<double>& costs, int count);

// A 64-bit FNV-1a hash, as 16 hex digits: a fingerprint of a run's inputs
// that shards and merge compare. It catches accidents (another build, another
// input), not forgery.
std::string fingerprint(std::string_view bytes);

}  // namespace bouncecheck
