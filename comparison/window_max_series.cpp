#include "comparison/window_max_series.h"

#include <algorithm>

namespace bouncecheck {

void WindowMaxSeries::add_periodic(PeriodicTail::Cursor at, std::span<const double> cycle) {
    const auto period = static_cast<std::int64_t>(cycle.size());
    std::int64_t phase = 0;  // of the next sample in `cycle`
    while (at.left() > 0) {
        const std::int64_t taken = std::min(at.left(), stride_ - in_window_);
        // Only the window's first occurrence of its largest value matters,
        // and all of them are among its first `period` samples.
        std::int64_t largest = -1;
        for (std::int64_t i = 0; i < std::min(taken, period); ++i) {
            const double value = cycle[static_cast<std::size_t>((phase + i) % period)];
            if ((in_window_ == 0 && i == 0) || value > window_max_) {
                window_max_ = value;
                largest = i;
            }
        }
        if (largest >= 0) window_t_ = at.t_ahead(largest);
        at.skip(taken);
        phase = (phase + taken) % period;
        if ((in_window_ += taken) == stride_) {
            t_.push_back(window_t_);
            v_.push_back(window_max_);
            in_window_ = 0;
        }
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
