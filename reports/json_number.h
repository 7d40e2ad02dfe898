// Numbers in the JSON reports (report.json, sweep.json, stress.json): a
// value that is not finite (not measured, undefined) is null, and so is an
// absent one. And the reports' text: json_text.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <optional>
#include <string>
#include <type_traits>

namespace bouncecheck {

inline nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

template <class T>
nlohmann::json json_number(const std::optional<T>& v) {
    if (!v) return nullptr;
    if constexpr (std::is_floating_point_v<T>) return json_number(static_cast<double>(*v));
    else return *v;
}

// A report's JSON as text. Strings from outside (an external's stderr and
// settings, a path given on the command line) may hold bytes that are not
// UTF-8: each such byte becomes U+FFFD rather than the whole report being
// lost to nlohmann's type_error.316.
inline std::string json_text(const nlohmann::json& j, int indent = -1) {
    return j.dump(indent, ' ', /*ensure_ascii=*/false, nlohmann::json::error_handler_t::replace);
}

}  // namespace bouncecheck
