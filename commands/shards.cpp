#include "commands/shards.h"

#include "platform/atomic_file.h"
#include "reports/provenance.h"
#include "reports/json_number.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <map>
#include <utility>

namespace fs = std::filesystem;

namespace bouncecheck {

void add_shard_option(CLI::App& command, std::string& shard) {
    command
        .add_option("--shard", shard,
                     "Run only part K of N of the pairs (K = 1..N), chosen by cost and the same on every machine; "
                     "`bouncecheck merge` puts the N output folders together (scripts/slurm/)")
        ->check(CLI::Validator(
            [](std::string& text) {
                std::string error;
                return parse_shard(text, error) ? std::string() : error;
            },
            "K/N"));
}

Shard shard_of(const std::string& text) {
    std::string error;
    return text.empty() ? Shard{} : parse_shard(text, error).value_or(Shard{});
}

WrittenFiles write_shard_file(const fs::path& out_dir, const ShardFile& file) {
    nlohmann::json results = nlohmann::json::array();
    for (const std::string& bytes : file.results)
        results.push_back(nlohmann::json::binary(std::vector<std::uint8_t>(bytes.begin(), bytes.end())));
    const nlohmann::json j = {{"schema", kShardSchema},
                              {"command", file.command},
                              {"shard", {file.shard.index, file.shard.count}},
                              {"pairs", file.pairs},
                              {"fingerprint", file.fingerprint},
                              {"options", file.options},
                              {"wall_seconds", file.wall_seconds},
                              {"slots", file.slots},
                              {"results", std::move(results)}};
    const std::vector<std::uint8_t> bytes = nlohmann::json::to_cbor(j);
    write_file_atomically(out_dir / kShardFileName,
                          std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
    return {kShardFileName};
}

std::string run_fingerprint(std::string_view command, std::string_view inputs) {
    const std::string build = json_text(to_json(this_provenance(/*with_machine=*/false)));
    return fingerprint(fmt::format("{}\n{}\n{}", build, command, inputs));
}

namespace {

std::optional<ShardFile> read_shard_file(const fs::path& dir) {
    const fs::path path = dir / kShardFileName;
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        fmt::print(stderr, "error: {}: cannot read {} (not an output folder of `stress --shard` or `sweep --shard`?)\n",
                   dir.string(), kShardFileName);
        return std::nullopt;
    }
    try {
        const nlohmann::json j = nlohmann::json::from_cbor(in);
        if (j.at("schema") != kShardSchema) {
            fmt::print(stderr, "error: {}: schema {}, expected \"{}\"\n", path.string(), j.at("schema").dump(),
                       kShardSchema);
            return std::nullopt;
        }
        ShardFile file;
        file.command = j.at("command").get<std::string>();
        file.shard = {j.at("shard").at(0).get<int>(), j.at("shard").at(1).get<int>()};
        file.pairs = j.at("pairs").get<std::size_t>();
        file.fingerprint = j.at("fingerprint").get<std::string>();
        file.options = j.at("options");
        file.wall_seconds = j.at("wall_seconds").get<double>();
        file.slots = j.at("slots").get<std::vector<std::size_t>>();
        for (const nlohmann::json& r : j.at("results")) {
            const auto& bytes = r.get_binary();
            file.results.emplace_back(bytes.begin(), bytes.end());
        }
        if (file.slots.size() != file.results.size())
            throw std::runtime_error(fmt::format("{} slots for {} results", file.slots.size(), file.results.size()));
        if (file.shard.index < 1 || file.shard.index > file.shard.count)
            throw std::runtime_error(fmt::format("shard {} is not K/N with 1 <= K <= N", to_string(file.shard)));
        return file;
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: {}: unreadable: {}\n", path.string(), e.what());
        return std::nullopt;
    }
}

}  // namespace

std::optional<ShardSet> read_shards(const std::vector<fs::path>& dirs) {
    std::vector<ShardFile> files;
    for (const fs::path& dir : dirs) {
        auto file = read_shard_file(dir);
        if (!file) return std::nullopt;
        files.push_back(std::move(*file));
    }
    const ShardFile& first = files.front();
    bool ok = true;
    std::map<int, std::size_t> by_index;  // shard index -> position in dirs
    for (std::size_t i = 0; i < files.size(); ++i) {
        const ShardFile& f = files[i];
        const auto differs = [&](const char* what, const std::string& mine, const std::string& theirs) {
            fmt::print(stderr, "error: {}: a shard of another run than {}: its {} is {}, not {}\n", dirs[i].string(),
                       dirs[0].string(), what, mine, theirs);
            ok = false;
        };
        if (f.command != first.command)
            differs("command", f.command, first.command);
        else if (f.fingerprint != first.fingerprint)
            differs("fingerprint (of the build and the inputs)", f.fingerprint, first.fingerprint);
        else if (f.shard.count != first.shard.count)
            differs("shard count", std::to_string(f.shard.count), std::to_string(first.shard.count));
        else if (f.pairs != first.pairs)
            differs("pair count", std::to_string(f.pairs), std::to_string(first.pairs));
        else if (const auto [seen, fresh] = by_index.emplace(f.shard.index, i); !fresh) {
            fmt::print(stderr, "error: {} and {} are both shard {}\n", dirs[seen->second].string(), dirs[i].string(),
                       to_string(f.shard));
            ok = false;
        }
    }
    if (!ok) return std::nullopt;
    std::vector<std::string> missing;
    for (int k = 1; k <= first.shard.count; ++k)
        if (!by_index.count(k)) missing.push_back(to_string(Shard{k, first.shard.count}));
    if (!missing.empty()) {
        fmt::print(stderr, "error: missing shard{} {} of the run ({} of {} given)\n", missing.size() > 1 ? "s" : "",
                   fmt::join(missing, ", "), files.size(), first.shard.count);
        return std::nullopt;
    }

    ShardSet set;
    set.command = first.command;
    set.options = first.options;
    set.fingerprint = first.fingerprint;
    set.results.resize(first.pairs);
    std::vector<int> owner(first.pairs, 0);  // the shard that gave each pair
    for (ShardFile& f : files) {  // their results move into the set: a large run's are gigabytes
        set.wall_seconds = std::max(set.wall_seconds, f.wall_seconds);
        for (std::size_t i = 0; i < f.slots.size(); ++i) {
            const std::size_t slot = f.slots[i];
            if (slot >= first.pairs || owner[slot] != 0) {
                fmt::print(stderr, "error: shard {}: pair {} is {}\n", to_string(f.shard), slot,
                           slot >= first.pairs ? fmt::format("beyond the run's {} pairs", first.pairs)
                                               : fmt::format("also shard {}'s", owner[slot]));
                return std::nullopt;
            }
            owner[slot] = f.shard.index;
            set.results[slot] = std::move(f.results[i]);
        }
    }
    if (const auto hole = std::find(owner.begin(), owner.end(), 0); hole != owner.end()) {
        fmt::print(stderr, "error: pair {} of the run is in no shard\n", std::distance(owner.begin(), hole));
        return std::nullopt;
    }
    return set;
}

bool shards_ran_this_plan(const ShardSet& shards, const std::string& planned) {
    if (planned == shards.fingerprint) return true;
    fmt::print(stderr,
               "error: the shards ran another build or other inputs than this merge sees (fingerprint {}, here {}): "
               "merge with the build, and the scenario files, the shards ran\n",
               shards.fingerprint, planned);
    return false;
}

}  // namespace bouncecheck
