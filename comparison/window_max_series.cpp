#include "comparison/window_max_series.h"

namespace bouncecheck {

std::vector<double> WindowMaxSeries::times() const {
    std::vector<double> out = t_;
    if (in_window_ > 0) out.push_back(window_t_);
    return out;
}

std::vector<double> WindowMaxSeries::values() const {
    std::vector<double> out = v_;
    if (in_window_ > 0) out.push_back(window_max_);
    return out;
}

}  // namespace bouncecheck
