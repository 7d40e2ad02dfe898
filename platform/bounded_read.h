// Reading a file that came from outside (a manifest, a shard, an external's
// settings): opened without waiting, so a FIFO in its place is refused
// rather than blocking the run; checked to be a regular file; refused from
// its size before a byte is read, so a huge or endless file costs nothing.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <variant>

namespace bouncecheck {

struct ReadRefusal {
    std::string reason;    // "not a regular file", "N bytes, over the limit of M", or the system's
    bool missing = false;  // there is no such file
};

enum class Links { follow, refuse };

// The contents of `file` if it is a regular file of at most `max_bytes`.
// With Links::refuse a symbolic link in its place is refused too.
std::variant<std::string, ReadRefusal> read_bounded(const std::filesystem::path& file, std::uintmax_t max_bytes,
                                                    Links links = Links::follow);

}  // namespace bouncecheck
