// A result across a worker process's channel (platform/parallel_pairs.h):
// CBOR, in which every double keeps its bits (NaN and infinities included),
// with an absent optional as null. The same bytes are a shard file's results
// (commands/shards.h), read back by merge from outside.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace bouncecheck::wire {

template <class T>
nlohmann::json optional(const std::optional<T>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

template <class T>
std::optional<T> optional_from(const nlohmann::json& j) {
    return j.is_null() ? std::nullopt : std::optional<T>(j.get<T>());
}

inline std::string to_bytes(const nlohmann::json& j) {
    const std::vector<std::uint8_t> bytes = nlohmann::json::to_cbor(j);
    return {bytes.begin(), bytes.end()};
}

// A result is a few levels deep. Bytes from outside (a shard file's results)
// are checked against this as they are read (commands/shards.cpp), before
// they reach from_bytes: nlohmann's decoder recurses once per level, and a
// result nested 200,000 deep overflowed the stack. A worker's own bytes are
// not checked again.
inline constexpr std::size_t kMaxResultDepth = 32;

inline nlohmann::json from_bytes(const std::string& bytes) { return nlohmann::json::from_cbor(bytes); }

}  // namespace bouncecheck::wire
