// A result across a worker process's channel (platform/parallel_pairs.h):
// CBOR, in which every double keeps its bits (NaN and infinities included),
// with an absent optional as null.
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

inline nlohmann::json from_bytes(const std::string& bytes) { return nlohmann::json::from_cbor(bytes); }

}  // namespace bouncecheck::wire
