// `bouncecheck merge --out OUT SHARD_DIR...` (or `merge OUT SHARD_DIR...`): the output folders of a run's N
// shards (`stress --shard K/N`, `sweep --shard K/N`) put back together into
// the files the unsharded run writes, byte for byte apart from timings.
#include "commands/command.h"

#include "commands/shards.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

struct MergeOptions {
    std::string out_dir;                  // --out; empty: the first folder given
    std::vector<std::string> folders;     // [OUT] SHARD_DIR...
    bool no_timings = false;
};

// Exit status: the unsharded command's (stress: 0, 1 or 3; sweep: 0 or 3),
// or 2 when the folders are not one complete run's shards.
int command_merge(const MergeOptions& opt) {
    // Without --out the first folder is the output, as `merge OUT SHARD_DIR...` always took it.
    const bool positional_out = opt.out_dir.empty();
    if (opt.folders.size() < (positional_out ? 2u : 1u)) {
        fmt::print(stderr, "error: merge: no shard folder given (merge --out OUT SHARD_DIR...)\n");
        return kBadInput;
    }
    const auto first_shard = opt.folders.begin() + (positional_out ? 1 : 0);
    std::vector<fs::path> dirs(first_shard, opt.folders.end());
    const auto shards = read_shards(dirs);
    if (!shards) return kBadInput;
    const fs::path out_dir = positional_out ? opt.folders.front() : opt.out_dir;
    auto out = OutputFolder::open(out_dir);
    if (!out) return kBadInput;
    if (shards->command == "stress") return merge_stress(*shards, *out, opt.no_timings);
    if (shards->command == "sweep") return merge_sweep(*shards, *out, opt.no_timings);
    fmt::print(stderr, "error: {}: shards of `{}`, which has no merge (stress and sweep do)\n", dirs.front().string(),
               shards->command);
    return kBadInput;
}

}  // namespace

Command add_merge_command(CLI::App& app) {
    auto opt = std::make_shared<MergeOptions>();
    CLI::App* command = app.add_subcommand(
        "merge", "Put the output folders of a run's shards (stress or sweep --shard K/N) together into the files "
                 "the unsharded run writes");
    command->add_option("--out", opt->out_dir, "Output folder for the merged files");
    command->add_option("folders", opt->folders,
                        "Every shard's output folder, in any order; without --out, the output folder first")
        ->required()
        ->expected(1, -1);
    add_no_timings_flag(*command, opt->no_timings);
    set_exit_status_help(*command, {{kOk, "merged; the unsharded command's status: stress 0, 1 or 3, sweep 0 or 3"},
                                   {kBadInput, "the folders are not one complete run's shards: nothing written"}});
    return {command, [opt] { return command_merge(*opt); }};
}

}  // namespace bouncecheck
