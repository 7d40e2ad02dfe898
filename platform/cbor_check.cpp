#include "platform/cbor_check.h"

#include <fmt/format.h>

#include <cstdint>
#include <vector>

namespace bouncecheck {

namespace {

// An open container: how many items it still takes (or an indefinite one,
// closed by a break byte), and whether only strings of `string_major` may
// come (an indefinite-length string's chunks).
struct Frame {
    std::uint64_t remaining = 0;
    bool indefinite = false;
    int string_major = -1;
};

}  // namespace

std::optional<std::string> cbor_problem(std::string_view bytes, std::size_t max_depth) {
    std::vector<Frame> open;
    std::size_t at = 0;
    bool top_done = false;
    const auto error = [&](std::size_t where, const std::string& why) {
        return fmt::format("byte {}: {}", where, why);
    };
    while (!top_done) {
        if (at >= bytes.size()) return error(at, "the data ends inside an item");
        const std::size_t start = at;
        const auto initial = static_cast<unsigned char>(bytes[at++]);
        const int major = initial >> 5, info = initial & 0x1f;
        // A break closes the innermost indefinite container.
        if (initial == 0xff) {
            if (open.empty() || !open.back().indefinite) return error(start, "a break outside an indefinite item");
            open.pop_back();
        } else {
            if (!open.empty() && open.back().string_major >= 0 && major != open.back().string_major)
                return error(start, "an indefinite string holds something other than its chunks");
            std::uint64_t argument = static_cast<std::uint64_t>(info);
            bool indefinite = false;
            if (info >= 24 && info <= 27) {
                const std::size_t n = std::size_t{1} << (info - 24);
                if (bytes.size() - at < n) return error(start, "the data ends inside an item's head");
                argument = 0;
                for (std::size_t i = 0; i < n; ++i) argument = (argument << 8) | static_cast<unsigned char>(bytes[at++]);
            } else if (info == 31) {
                if (major == 0 || major == 1 || major == 6 || major == 7) return error(start, "a malformed head");
                indefinite = true;
            } else if (info >= 28) {
                return error(start, "a reserved head");
            }
            const std::uint64_t left = bytes.size() - at;
            bool complete = true;  // this item is whole once its head is read
            switch (major) {
            case 2:
            case 3:
                if (indefinite) {
                    if (!open.empty() && open.back().string_major >= 0)
                        return error(start, "an indefinite string inside another");
                    open.push_back({0, true, major});
                    complete = false;
                } else {
                    if (argument > left) return error(start, "a string longer than the data left");
                    at += static_cast<std::size_t>(argument);
                }
                break;
            case 4:
            case 5: {
                const std::uint64_t items = major == 5 ? argument * 2 : argument;
                if (!indefinite && (argument > left || items > left))
                    return error(start, fmt::format("{} items claimed, with {} bytes left", items, left));
                if (indefinite || items > 0) {
                    open.push_back({items, indefinite, -1});
                    complete = false;
                }
                break;
            }
            case 6:  // a tag: the next item is its content
                open.push_back({1, false, -1});
                complete = false;
                break;
            default:  // 0, 1 integers (the head is all); 7 simple values and floats
                break;
            }
            if (open.size() > max_depth) return error(start, fmt::format("nested deeper than {} levels", max_depth));
            if (!complete) continue;
        }
        // An item is whole: it fills a slot of its container, which may close it, and so on up.
        for (;;) {
            if (open.empty()) {
                top_done = true;
                break;
            }
            Frame& f = open.back();
            if (f.indefinite) break;
            if (--f.remaining > 0) break;
            open.pop_back();
        }
    }
    if (at != bytes.size()) return error(at, fmt::format("{} bytes after the data item", bytes.size() - at));
    return std::nullopt;
}

}  // namespace bouncecheck
