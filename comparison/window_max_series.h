// A distance over time as the HTML report plots it: memory bounded by the
// number of windows, not by the run's length.
#pragma once

#include "simulators/state.h"

#include <algorithm>
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
        State at;
        at.t = t;
        add({&at, 1}, &value);
    }
    // values[i] at states[i].t, the same as add() of each: a window at a
    // time, the open window's figures in registers (as members, every
    // sample stored and reloaded them).
    void add(std::span<const State> states, const double* values) {
        std::int64_t in_window = in_window_;
        double window_t = window_t_, window_max = window_max_;
        for (std::size_t i = 0; i < states.size();) {
            const std::size_t end = std::min(states.size(), i + static_cast<std::size_t>(stride_ - in_window));
            if (in_window == 0) {  // a window's first value opens it, whatever it is
                window_max = values[i];
                window_t = states[i].t;
                ++i;
                ++in_window;
            }
            for (; i < end; ++i, ++in_window) {
                if (values[i] > window_max) {
                    window_max = values[i];
                    window_t = states[i].t;
                }
            }
            if (in_window == stride_) {
                t_.push_back(window_t);
                v_.push_back(window_max);
                in_window = 0;
            }
        }
        in_window_ = in_window;
        window_t_ = window_t;
        window_max_ = window_max;
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
