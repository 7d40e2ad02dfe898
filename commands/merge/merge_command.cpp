// `bouncecheck merge OUT SHARD_DIR...`: the output folders of a run's N
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
    std::string out_dir;
    std::vector<std::string> shard_dirs;
};

// Exit status: the unsharded command's (stress: 0, 1 or 3; sweep: 0 or 3),
// or 2 when the folders are not one complete run's shards.
int command_merge(const MergeOptions& opt) {
    std::vector<fs::path> dirs(opt.shard_dirs.begin(), opt.shard_dirs.end());
    const auto shards = read_shards(dirs);
    if (!shards) return kBadInput;
    const fs::path out_dir = opt.out_dir;
    if (!create_out_dir(out_dir)) return kBadInput;
    if (shards->command == "stress") return merge_stress(*shards, out_dir);
    if (shards->command == "sweep") return merge_sweep(*shards, out_dir);
    fmt::print(stderr, "error: {}: shards of `{}`, which has no merge (stress and sweep do)\n", opt.shard_dirs.front(),
               shards->command);
    return kBadInput;
}

}  // namespace

Command add_merge_command(CLI::App& app) {
    auto opt = std::make_shared<MergeOptions>();
    CLI::App* command = app.add_subcommand(
        "merge", "Put the output folders of a run's shards (stress or sweep --shard K/N) together into the files "
                 "the unsharded run writes");
    command->add_option("out", opt->out_dir, "Output folder for the merged files")->required();
    command->add_option("shards", opt->shard_dirs, "Every shard's output folder, in any order")
        ->required()
        ->expected(1, -1);
    return {command, [opt] { return command_merge(*opt); }};
}

}  // namespace bouncecheck
