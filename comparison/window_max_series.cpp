#include "comparison/window_max_series.h"

namespace bouncecheck {

void WindowMaxSeries::add(double t, double value) {
    if (in_window_ == 0 || value > window_max_) {
        window_max_ = value;
        window_t_ = t;
    }
    if (++in_window_ == stride_) {
        t_.push_back(window_t_);
        v_.push_back(window_max_);
        in_window_ = 0;
    }
}

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
