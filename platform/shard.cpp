#include "platform/shard.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <numeric>
#include <queue>
#include <utility>

namespace bouncecheck {

namespace {

std::optional<int> whole_number(std::string_view text) {
    int value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
    return value;
}

}  // namespace

std::optional<Shard> parse_shard(std::string_view text, std::string& error) {
    const auto slash = text.find('/');
    const auto k = slash == std::string_view::npos ? std::nullopt : whole_number(text.substr(0, slash));
    const auto n = slash == std::string_view::npos ? std::nullopt : whole_number(text.substr(slash + 1));
    if (!k || !n) {
        error = fmt::format("'{}': expected K/N, two whole numbers (e.g. 3/8)", text);
        return std::nullopt;
    }
    if (*n < 1 || *n > kMaxShards) {
        error = fmt::format("'{}': N must be 1 to {}", text, kMaxShards);
        return std::nullopt;
    }
    if (*k < 1 || *k > *n) {
        error = fmt::format("'{}': K must be 1 to N (shards are numbered from 1)", text);
        return std::nullopt;
    }
    return Shard{*k, *n};
}

std::string to_string(const Shard& s) { return fmt::format("{}/{}", s.index, s.count); }

std::vector<int> assign_shards(const std::vector<double>& costs, int count) {
    std::vector<std::size_t> order(costs.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return costs[a] > costs[b]; });
    // The least-loaded shard on top; equal loads: the lower shard.
    using Load = std::pair<double, int>;
    std::priority_queue<Load, std::vector<Load>, std::greater<>> loads;
    for (int shard = 1; shard <= count; ++shard) loads.emplace(0.0, shard);
    std::vector<int> shard_of(costs.size(), 1);
    for (std::size_t pair : order) {
        auto [load, shard] = loads.top();
        loads.pop();
        shard_of[pair] = shard;
        loads.emplace(load + costs[pair], shard);
    }
    return shard_of;
}

std::string fingerprint(std::string_view bytes) {
    std::uint64_t hash = 0xcbf29ce484222325ULL;
    for (unsigned char c : bytes) {
        hash ^= c;
        hash *= 0x100000001b3ULL;
    }
    return fmt::format("{:016x}", hash);
}

}  // namespace bouncecheck
