// A result across a worker process's channel (platform/parallel_pairs.h):
// CBOR, in which every double keeps its bits (NaN and infinities included),
// with an absent optional as null. The same bytes are a shard file's results
// (commands/shards.h), read back by merge from outside.
#pragma once

#include "platform/cbor_check.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <stdexcept>
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

// A result is a few levels deep; a deeper one is not ours.
inline constexpr std::size_t kMaxResultDepth = 32;

// Decodes a result; throws std::runtime_error saying why bytes are not one.
// Checked first: nlohmann's decoder recurses once per level, and a shard's
// result nested 200,000 deep (a valid digest recomputed) overflowed the stack.
inline nlohmann::json from_bytes(const std::string& bytes) {
    if (auto problem = cbor_problem(bytes, kMaxResultDepth)) throw std::runtime_error(*problem);
    return nlohmann::json::from_cbor(bytes);
}

}  // namespace bouncecheck::wire
