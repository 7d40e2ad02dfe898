// Numbers in the JSON reports (report.json, sweep.json, stress.json): a
// value that is not finite (not measured, undefined) is null, and so is an
// absent one.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <optional>
#include <type_traits>

namespace bouncecheck {

inline nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

template <class T>
nlohmann::json json_number(const std::optional<T>& v) {
    if (!v) return nullptr;
    if constexpr (std::is_floating_point_v<T>) return json_number(static_cast<double>(*v));
    else return *v;
}

}  // namespace bouncecheck
