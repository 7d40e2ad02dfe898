// A run spread over shards (`stress --shard K/N`, `sweep --shard K/N`) and
// put back together (`bouncecheck merge`): the file each shard writes beside
// its partial results, and the checks merge makes before it trusts a set of
// them. Each shard's pairs are platform/shard.h's assignment.
#pragma once

#include "platform/output_manifest.h"
#include "platform/shard.h"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace CLI {
class App;
}

namespace bouncecheck {

inline constexpr const char* kShardFileName = "shard.cbor";
inline constexpr const char* kShardSchema = "bouncecheck-shard/1";
// A shard file holds its pairs' results: a million-scenario stress shard's
// are gigabytes. Past this it is not one; nested past kMaxShardFileDepth it
// is refused before it is decoded (the format nests 6 levels at most).
inline constexpr std::uintmax_t kMaxShardFileBytes = std::uintmax_t{64} << 30;
inline constexpr std::size_t kMaxShardFileDepth = 32;

// --shard K/N.
void add_shard_option(CLI::App& command, std::string& shard);
// The option's value as parsed (CLI11 has checked it); the whole run if empty.
Shard shard_of(const std::string& text);

// What a shard hands to merge (DIR/shard.cbor, CBOR, so that every double keeps its bits).
struct ShardFile {
    std::string command;       // "stress" or "sweep"
    Shard shard;
    std::size_t pairs = 0;     // of the whole run
    std::string fingerprint;   // run_fingerprint: the build and the inputs
    nlohmann::json options;    // the command's options: merge plans the same run from them
    double wall_seconds = 0;
    std::vector<std::size_t> slots;    // the shard's pairs, in the whole run's order
    std::vector<std::string> results;  // each pair's result as the pipeline encodes it
};
// Writes DIR/shard.cbor atomically; returns its name.
WrittenFiles write_shard_file(const std::filesystem::path& out_dir, const ShardFile& file);

// The fingerprint of a run: this build (its provenance block without the
// machine), the command, and `inputs` (the options that choose the work, and
// what they expanded to: every scenario, every simulator).
std::string run_fingerprint(std::string_view command, std::string_view inputs);

// A complete set of shards of one run, read and checked: each directory's
// shard file readable; the same command, shard count, pair count and
// fingerprint in all; no shard twice; none missing; every pair once.
struct ShardSet {
    std::string command;
    nlohmann::json options;
    std::string fingerprint;
    double wall_seconds = 0;           // the slowest shard's
    std::vector<std::string> results;  // every pair's, in slot order
};
// Prints every problem, naming the directory; nothing on failure.
std::optional<ShardSet> read_shards(const std::vector<std::filesystem::path>& dirs);

// Whether `shards` ran the plan whose fingerprint is `planned` (the merge's
// own plan of the same options); prints why not.
bool shards_ran_this_plan(const ShardSet& shards, const std::string& planned);

// Each command's merge: plans the run again from the shards' options, refuses
// shards whose fingerprint is not this plan's, and writes exactly what the
// unsharded run writes, returning its exit status. In
// commands/stress/stress_command.cpp and commands/sweep/sweep_command.cpp.
int merge_stress(const ShardSet& shards, OutputFolder& out, bool no_timings);
int merge_sweep(const ShardSet& shards, OutputFolder& out, bool no_timings);

}  // namespace bouncecheck
