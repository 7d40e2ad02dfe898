// A distance over time as the HTML report plots it: memory bounded by the
// number of windows, not by the run's length.
#pragma once

#include "simulators/state.h"

#include <cstdint>
#include <span>
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
    // The rest of a periodic tail: the sample `at` will make next has value
    // cycle[0], the one after cycle[1 % size], and so on. Same result as
    // add() for each, in O(windows x min(stride, cycle) + log) instead of O(samples).
    void add_periodic(PeriodicTail::Cursor at, std::span<const double> cycle);
    // The values so far, the current partial window included.
    std::vector<double> times() const;
    std::vector<double> values() const;

private:
    std::int64_t stride_, in_window_ = 0;
    double window_t_ = 0, window_max_ = -1;
    std::vector<double> t_, v_;
};

}  // namespace bouncecheck
