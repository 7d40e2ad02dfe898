// Test helper: the observed order of convergence, as the sweep reports it.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

namespace bouncecheck::test {

// Least-squares slope of log(error) against log(dt).
inline double fitted_order(const std::vector<double>& dts, const std::vector<double>& errors) {
    double mx = 0, my = 0;
    const double n = static_cast<double>(dts.size());
    for (std::size_t i = 0; i < dts.size(); ++i) {
        mx += std::log(dts[i]) / n;
        my += std::log(errors[i]) / n;
    }
    double sxy = 0, sxx = 0;
    for (std::size_t i = 0; i < dts.size(); ++i) {
        sxy += (std::log(dts[i]) - mx) * (std::log(errors[i]) - my);
        sxx += (std::log(dts[i]) - mx) * (std::log(dts[i]) - mx);
    }
    return sxy / sxx;
}

}  // namespace bouncecheck::test
