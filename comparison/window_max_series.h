// A distance over time as the HTML report plots it: memory bounded by the
// number of windows, not by the run's length.
#pragma once

#include <cstdint>
#include <vector>

namespace bouncecheck {

// A distance over time, decimated by keeping the largest value of each
// window of `stride` samples (with its time), so no spike is lost.
class WindowMaxSeries {
public:
    explicit WindowMaxSeries(std::int64_t stride) : stride_(stride < 1 ? 1 : stride) {}
    void add(double t, double value) {
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
    // The values so far, the current partial window included.
    std::vector<double> times() const;
    std::vector<double> values() const;

private:
    std::int64_t stride_, in_window_ = 0;
    double window_t_ = 0, window_max_ = -1;
    std::vector<double> t_, v_;
};

}  // namespace bouncecheck
