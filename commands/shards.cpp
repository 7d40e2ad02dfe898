#include "commands/shards.h"

#include "platform/atomic_file.h"
#include "platform/bounded_read.h"
#include "platform/cbor_check.h"
#include "commands/wire.h"
#include "platform/digest.h"
#include "platform/printable_text.h"
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
#include <variant>

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

namespace {

// What the digest covers: every field merge uses, each length-prefixed, so
// that a flipped byte anywhere in them is noticed (CBOR that stays valid
// after a flip otherwise merges silently: a tolerance 0.025 became 0.026953125).
std::string shard_digest(const ShardFile& file) {
    Fnv1a64 hash;
    const auto field = [&](std::string_view bytes) { hash.add(fmt::format("{}:", bytes.size())).add(bytes); };
    field(file.command);
    field(fmt::format("{}/{} {} {:a}", file.shard.index, file.shard.count, file.pairs, file.wall_seconds));
    field(file.fingerprint);
    field(json_text(file.options));
    for (const std::size_t slot : file.slots) field(std::to_string(slot));
    for (const std::string& result : file.results) field(result);
    return fmt::format("{:016x}", hash.value());
}

}  // namespace

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
                              {"results", std::move(results)},
                              {"digest", shard_digest(file)}};
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
    if (!fs::exists(fs::symlink_status(path))) {
        fmt::print(stderr, "error: {}: cannot read {} (not an output folder of `stress --shard` or `sweep --shard`?)\n",
                   dir.string(), kShardFileName);
        return std::nullopt;
    }
    // Without waiting (a FIFO in its place is refused), and refused from its size.
    auto read = read_bounded(path, kMaxShardFileBytes);
    if (auto* refused = std::get_if<ReadRefusal>(&read)) {
        fmt::print(stderr, "error: {}: cannot read: {}\n", path.string(), refused->reason);
        return std::nullopt;
    }
    const std::string& bytes = std::get<std::string>(read);
    try {
        // Checked before decoding: nlohmann's decoder recurses once per level.
        if (auto problem = cbor_problem(bytes, kMaxShardFileDepth)) throw std::runtime_error(*problem);
        const nlohmann::json j = nlohmann::json::from_cbor(bytes);
        if (j.at("schema") != kShardSchema) {
            fmt::print(stderr, "error: {}: schema {}, expected \"{}\"\n", path.string(), json_text(j.at("schema")),
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
            // A result is CBOR of its own, decoded later: its nesting is
            // checked here, where the file can still be named.
            if (auto problem = cbor_problem(file.results.back(), wire::kMaxResultDepth))
                throw std::runtime_error(fmt::format("result {}: {}", file.results.size(), *problem));
        }
        if (file.slots.size() != file.results.size())
            throw std::runtime_error(fmt::format("{} slots for {} results", file.slots.size(), file.results.size()));
        if (file.shard.count < 1 || file.shard.count > kMaxShards || file.shard.index < 1 ||
            file.shard.index > file.shard.count)
            throw std::runtime_error(fmt::format("shard {} is not K/N with 1 <= K <= N <= {}", to_string(file.shard),
                                                 kMaxShards));
        if (!j.contains("digest"))
            throw std::runtime_error("no digest (written by an older bouncecheck: run the shard again)");
        if (j.at("digest").get<std::string>() != shard_digest(file))
            throw std::runtime_error("its digest does not match its contents: the file changed after it was written");
        return file;
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: {}: unreadable: {}\n", printable_text(path.string()), error_text(e));
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
    if (files.size() < static_cast<std::size_t>(first.shard.count)) {
        // The first few missing, found among the first files.size() + 5 indices.
        std::vector<std::string> missing;
        for (int k = 1; k <= first.shard.count && missing.size() < 5; ++k)
            if (!by_index.count(k)) missing.push_back(to_string(Shard{k, first.shard.count}));
        const std::size_t count = static_cast<std::size_t>(first.shard.count) - files.size();
        fmt::print(stderr, "error: missing shard{} {}{} of the run ({} of {} given)\n", count > 1 ? "s" : "",
                   fmt::join(missing, ", "), count > missing.size() ? fmt::format(" and {} more", count - missing.size()) : "",
                   files.size(), first.shard.count);
        return std::nullopt;
    }
    // The header's pair count against the pairs the shards hold, before
    // anything is sized by it.
    std::size_t held = 0;
    for (const ShardFile& f : files) held += f.slots.size();
    if (held != first.pairs) {
        fmt::print(stderr, "error: the shards hold {} pairs, where their headers say the run has {}\n", held,
                   first.pairs);
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
