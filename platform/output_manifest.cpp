#include "platform/output_manifest.h"

#include "platform/printable_text.h"

#include "platform/atomic_file.h"
#include "platform/bounded_read.h"
#include "platform/digest.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fcntl.h>
#include <map>
#include <set>
#include <sys/stat.h>
#include <unistd.h>

namespace bouncecheck {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kKinds[] = {"run", "sweep", "stress", "diff"};
constexpr std::size_t kMaxPath = 1024;

bool known_kind(std::string_view kind) { return std::find(std::begin(kKinds), std::end(kKinds), kind) != std::end(kKinds); }

// Why `path` cannot be a manifest entry, or nothing: only the names
// bouncecheck writes (fixed names, scenario and simulator names), relative
// and inside the folder.
std::optional<std::string> path_problem(std::string_view path) {
    if (path.empty()) return "empty path";
    if (path.size() > kMaxPath) return fmt::format("path longer than {} characters", kMaxPath);
    for (char c : path) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                        c == '_' || c == '-' || c == '/';
        if (!ok) return "path holds a character other than letters, digits, . _ - and /";
    }
    if (path.front() == '/') return "path is absolute";
    std::size_t start = 0;
    while (start <= path.size()) {
        const std::size_t end = std::min(path.find('/', start), path.size());
        const std::string_view part = path.substr(start, end - start);
        if (part.empty()) return "path has an empty component";
        if (part == "." || part == "..") return "path has a . or .. component";
        start = end + 1;
    }
    if (path == kManifestFileName) return "the manifest lists itself";
    return std::nullopt;
}

bool parse_hex(std::string_view text, std::uint64_t& out) {
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out, 16);
    return ec == std::errc() && end == text.data() + text.size();
}

template <typename Int>
bool parse_int(std::string_view text, Int& out) {
    if (text.empty() || text.size() > 20) return false;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
    return ec == std::errc() && end == text.data() + text.size();
}


// `relative` under `dir` as a regular file reached through real folders
// only (no symbolic link on the way), or nothing.
std::optional<fs::path> regular_file_inside(const fs::path& dir, const std::string& relative) {
    fs::path p = dir;
    const fs::path rel(relative);
    for (auto part = rel.begin(); part != rel.end(); ++part) {
        p /= *part;
        std::error_code ec;
        const fs::file_status st = fs::symlink_status(p, ec);
        if (ec) return std::nullopt;
        const bool last = std::next(part) == rel.end();
        if (last ? st.type() != fs::file_type::regular : st.type() != fs::file_type::directory) return std::nullopt;
    }
    return p;
}

// The entry `relative` has now, or nothing when it is not a regular file in the folder.
std::optional<ManifestEntry> entry_now(const fs::path& dir, const std::string& kind, const std::string& relative) {
    const auto p = regular_file_inside(dir, relative);
    if (!p) return std::nullopt;
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(*p, ec);
    if (ec) return std::nullopt;
    const auto digest = file_digest(*p);
    if (!digest) return std::nullopt;
    return ManifestEntry{kind, size, *digest, relative};
}

// Whether a listed file is still as it was written; its contents are read
// only when its size still matches.
enum class Listed { gone, changed, unchanged };
Listed listed_now(const fs::path& dir, const ManifestEntry& before) {
    const auto p = regular_file_inside(dir, before.path);
    if (!p) return Listed::gone;
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(*p, ec);
    if (ec) return Listed::gone;
    if (size != before.size) return Listed::changed;
    const auto digest = file_digest(*p);
    if (!digest) return Listed::gone;
    return *digest == before.digest ? Listed::unchanged : Listed::changed;
}

// Reads the manifest of `dir`: nothing when there is none; an error text
// (naming the file and line) when it cannot be read or parsed.
std::variant<Manifest, std::string> read_manifest(const fs::path& dir) {
    const fs::path path = dir / kManifestFileName;
    // Without waiting: a FIFO in its place must not hang the run.
    auto read = read_bounded(path, kManifestMaxBytes, Links::refuse);
    if (auto* refused = std::get_if<ReadRefusal>(&read)) {
        if (refused->missing) return Manifest{};  // a folder no command wrote into yet
        return fmt::format("{}: {}", path.string(), refused->reason);
    }
    const std::string& text = std::get<std::string>(read);
    auto parsed = parse_manifest(text);
    if (auto* error = std::get_if<std::string>(&parsed))
        return fmt::format("{}:{} (delete the file to start the folder's list afresh)", path.string(), *error);
    return parsed;
}

// Removes the folders between `file`'s folder and `dir` that are now empty.
void remove_empty_parents(const fs::path& dir, fs::path file) {
    for (fs::path p = file.parent_path(); p != dir && p.native().size() > dir.native().size(); p = p.parent_path()) {
        std::error_code ec;
        if (!fs::is_empty(p, ec) || ec) return;
        fs::remove(p, ec);
        if (ec) return;
    }
}

std::string names(const std::vector<std::string>& paths) {
    constexpr std::size_t kShown = 5;
    std::string out;
    for (std::size_t i = 0; i < std::min(paths.size(), kShown); ++i) out += (i ? ", " : "") + paths[i];
    if (paths.size() > kShown) out += fmt::format(" and {} more", paths.size() - kShown);
    return out;
}

}  // namespace

std::optional<std::uint64_t> file_digest(const fs::path& file) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return std::nullopt;
    Fnv1a64 hash;
    std::string buffer(1 << 16, '\0');
    for (;;) {
        const ssize_t n = ::read(fd, buffer.data(), buffer.size());
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            ::close(fd);
            return std::nullopt;
        }
        if (n == 0) break;
        hash.add(std::string_view(buffer.data(), static_cast<std::size_t>(n)));
    }
    ::close(fd);
    return hash.value();
}

std::variant<Manifest, std::string> parse_manifest(std::string_view text) {
    Manifest m;
    if (!text.empty() && text.back() != '\n') {
        const std::size_t lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
        return fmt::format("{}: the last line is cut off (no newline at the end)", lines);
    }
    std::set<std::string_view> seen;
    std::size_t line_no = 0, start = 0;
    while (start < text.size()) {
        const std::size_t end = text.find('\n', start);
        const std::string_view line = text.substr(start, end - start);
        start = end + 1;
        ++line_no;
        if (line.size() > kManifestMaxLine)
            return fmt::format("{}: line longer than {} bytes", line_no, kManifestMaxLine);
        if (line_no == 1) {
            if (line.substr(0, std::strlen(kManifestHeader)) != kManifestHeader)
                return fmt::format("1: not a bouncecheck manifest (the first line is not '{}')", kManifestHeader);
            continue;
        }
        if (!line.empty() && line.front() == '#') continue;
        std::string_view fields[4];
        std::size_t count = 0, from = 0;
        while (count < 4) {
            const std::size_t tab = line.find('\t', from);
            fields[count++] = line.substr(from, tab == std::string_view::npos ? std::string_view::npos : tab - from);
            if (tab == std::string_view::npos) break;
            from = tab + 1;
            if (count == 4) return fmt::format("{}: more than 4 tab-separated fields", line_no);
        }
        if (count != 4) return fmt::format("{}: {} fields where 4 are expected (kind, size, digest, path)", line_no, count);
        ManifestEntry e;
        if (!known_kind(fields[0])) return fmt::format("{}: kind: unknown kind of output", line_no);
        e.kind = std::string(fields[0]);
        if (!parse_int(fields[1], e.size)) return fmt::format("{}: size: not a whole number of bytes", line_no);
        if (fields[2].size() != 16 || !parse_hex(fields[2], e.digest))
            return fmt::format("{}: digest: not 16 hexadecimal digits", line_no);
        if (auto problem = path_problem(fields[3])) return fmt::format("{}: path: {}", line_no, *problem);
        if (!seen.insert(fields[3]).second) return fmt::format("{}: path: listed twice", line_no);
        e.path = std::string(fields[3]);
        m.entries.push_back(std::move(e));
    }
    if (line_no == 0) return std::string("1: empty (not even the header line)");
    return m;
}

std::string format_manifest(const Manifest& m) {
    std::string out = fmt::format(
        "{}\n# The files bouncecheck wrote in this folder: kind of output, size, FNV-1a digest, path.\n"
        "# A command writing the same kind here again removes that kind's files it does not rewrite,\n"
        "# unless they changed since. Files not listed are never touched.\n",
        kManifestHeader);
    for (const ManifestEntry& e : m.entries) out += fmt::format("{}\t{}\t{:016x}\t{}\n", e.kind, e.size, e.digest, e.path);
    return out;
}

std::optional<OutputFolder> OutputFolder::open(const fs::path& dir, std::string* error) {
    const auto refuse = [&](std::string why) -> std::optional<OutputFolder> {
        if (error) *error = std::move(why);
        else fmt::print(stderr, "error: {}\n", why);
        return std::nullopt;
    };
    const std::string shown = printable_text(dir.string());
    if (dir.empty()) return refuse("--out: the folder's name is empty");
    std::error_code ec;
    fs::create_directories(dir, ec);  // the system's reason alone, not the library's wrapping of it
    if (ec) return refuse(fmt::format("--out: cannot create {}: {}", shown, ec.message()));
    if (!fs::is_directory(dir, ec)) return refuse(fmt::format("--out: {} is not a folder", shown));
    // Found now, not after every simulation has run.
    const fs::path probe = dir / fmt::format(".bouncecheck-write-check.{}", ::getpid());
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0) return refuse(fmt::format("--out: cannot write in {}: {}", shown, std::strerror(errno)));
    ::close(fd);
    ::unlink(probe.c_str());
    auto previous = read_manifest(dir);
    if (auto* why = std::get_if<std::string>(&previous)) return refuse(*why);
    return OutputFolder(dir, std::move(std::get<Manifest>(previous)));
}

ManifestUpdate OutputFolder::record(std::string_view kind_view, const WrittenFiles& written) {
    const std::string kind(kind_view);
    ManifestUpdate update;
    std::map<std::string, ManifestEntry> now;  // by path: sorted, so the manifest's bytes follow its contents
    for (const std::string& path : written) {
        if (path_problem(path)) continue;  // not a name bouncecheck writes: never listed
        if (auto e = entry_now(dir_, kind, path)) now[path] = std::move(*e);
    }
    for (const ManifestEntry& before : previous_.entries) {
        if (now.count(before.path)) continue;  // written again: its new entry stands
        if (before.kind != kind) {
            // Another kind's output stays listed while it is there; its own next write checks it.
            if (regular_file_inside(dir_, before.path)) now[before.path] = before;
            continue;
        }
        const Listed state = listed_now(dir_, before);
        if (state == Listed::gone) continue;  // (or no longer a plain file in the folder): nothing to list
        if (state == Listed::changed) {
            update.changed.push_back(before.path);
            continue;
        }
        std::error_code ec;
        if (fs::remove(dir_ / before.path, ec) && !ec) {
            update.removed.push_back(before.path);
            remove_empty_parents(dir_, dir_ / before.path);
        } else {
            now[before.path] = before;  // could not remove it: still ours, still listed
        }
    }
    Manifest next;
    for (auto& [path, e] : now) next.entries.push_back(std::move(e));
    write_file_atomically(dir_ / kManifestFileName, format_manifest(next));
    previous_ = std::move(next);
    return update;
}

std::string format_manifest_update(const ManifestUpdate& u, const fs::path& dir) {
    std::string out;
    if (!u.removed.empty())
        out += fmt::format("removed {} file{} an earlier run wrote in {} and this one did not: {}\n", u.removed.size(),
                           u.removed.size() == 1 ? "" : "s", dir.string(), names(u.removed));
    if (!u.changed.empty())
        out += fmt::format("left {} earlier file{} in place, changed since bouncecheck wrote {}: {}\n", u.changed.size(),
                           u.changed.size() == 1 ? "" : "s", u.changed.size() == 1 ? "it" : "them", names(u.changed));
    return out;
}

}  // namespace bouncecheck
