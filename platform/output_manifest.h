// Output folders that never mislead: each folder a command writes into keeps
// a manifest (bouncecheck-manifest.tsv) of the files bouncecheck wrote there,
// each under the kind of output it belongs to ("run", "sweep", "stress",
// "diff"). When the same kind is written again, its earlier files that this
// time does not rewrite are removed, so no stale file (a trajectory CSV of a
// simulator no longer run, a shard file beside a whole run's results) sits
// beside the new ones looking current. A file no bouncecheck run wrote is
// never listed, so never touched; neither is a listed file that changed
// since it was written (its size or contents differ): it is only dropped
// from the list, and named. The manifest holds no time, so under
// --no-timings it too is a function of the input.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace bouncecheck {

inline constexpr const char* kManifestFileName = "bouncecheck-manifest.tsv";
inline constexpr const char* kManifestHeader = "# bouncecheck-manifest/1";
// The manifest is read whole; a folder of a million stress scenarios lists
// about 60 MB. Anything larger is not one of ours.
inline constexpr std::uintmax_t kManifestMaxBytes = 128u << 20;
inline constexpr std::size_t kManifestMaxLine = 4096;

// The files a command wrote, relative to its output folder.
using WrittenFiles = std::vector<std::string>;

struct ManifestEntry {
    std::string kind;   // the output it belongs to: run, sweep, stress, diff
    std::uintmax_t size = 0;
    std::uint64_t digest = 0;   // FNV-1a of its contents when it was written
    std::string path;   // relative to the folder: letters, digits, . _ - and /, no "..", no leading /
};

struct Manifest {
    std::vector<ManifestEntry> entries;
};

// The FNV-1a 64-bit digest of a file's contents; nothing when it cannot be read.
std::optional<std::uint64_t> file_digest(const std::filesystem::path& file);

// Parses a manifest's text; an error is "line N: REASON".
std::variant<Manifest, std::string> parse_manifest(std::string_view text);
std::string format_manifest(const Manifest& m);

// What replacing a kind's files did.
struct ManifestUpdate {
    std::vector<std::string> removed;  // the kind's earlier files not written again
    std::vector<std::string> changed;  // earlier files changed since written: left in place, no longer listed
};

// An output folder, opened before a command runs anything and updated after
// it wrote its files.
class OutputFolder {
public:
    // Creates `dir` if needed, checks that a file can be created in it and
    // reads its manifest. On failure gives the reason (naming the folder or
    // the manifest's line) in `error`, or prints it on stderr without one,
    // and returns nothing: the caller exits 2 before running anything.
    static std::optional<OutputFolder> open(const std::filesystem::path& dir, std::string* error = nullptr);

    const std::filesystem::path& dir() const { return dir_; }

    // After the command wrote `written` (paths relative to the folder) as
    // output of `kind`: removes that kind's earlier files it did not write
    // again (and folders this leaves empty), then writes the manifest
    // atomically. Files of other kinds stay listed while they exist.
    ManifestUpdate record(std::string_view kind, const WrittenFiles& written);

private:
    OutputFolder(std::filesystem::path dir, Manifest previous) : dir_(std::move(dir)), previous_(std::move(previous)) {}
    std::filesystem::path dir_;
    Manifest previous_;
};

// The terminal's line for an update, or "" when it removed and dropped nothing.
std::string format_manifest_update(const ManifestUpdate& u, const std::filesystem::path& dir);

}  // namespace bouncecheck
