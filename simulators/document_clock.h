// The document's time loop, shared by every simulator that samples on it.
//
// The document runs `t = 0; while abs(t) < abs(simLength) ... t = t + dt`, so
// the sample times are the floating-point partial sums of dt, and the step
// count is not always duration / dt (see tests/data/README.md). Their
// rounding has a closed form per binade (simulators/repeated_addition.h), so
// a jump of n steps and the count of steps left cost O(log n), not O(n).
#pragma once

#include "simulators/repeated_addition.h"

#include <cmath>
#include <cstdint>

namespace bouncecheck {

// Steps the document's loop takes for (dt, duration).
std::int64_t document_step_count(double dt, double duration);

// Iterates the document's sample times t_0 = 0, t_{n+1} = t_n + dt.
class DocumentClock {
public:
    DocumentClock(double dt, double duration) : dt_(dt), duration_(duration) {}
    double t() const { return t_; }
    // True while the loop would take another step from the current t.
    bool running() const { return std::abs(t_) < std::abs(duration_); }
    void advance() { t_ = t_ + dt_; }
    // n advance()s at once, with the same t.
    void advance(std::int64_t n) { t_ = sum_after(t_, dt_, n); }
    // The states the run still takes after this one: the advance()s until
    // running() is false. A loop that never ends (t stops growing) counts
    // as INT64_MAX; the scenario loader's step limit rules that out.
    std::int64_t remaining_steps() const;

private:
    double dt_;
    double duration_;
    double t_ = 0.0;
};

}  // namespace bouncecheck
