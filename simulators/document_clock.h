// The document's time loop, shared by every simulator that samples on it.
//
// The document runs `t = 0; while abs(t) < abs(simLength) ... t = t + dt`, so
// the sample times are the floating-point partial sums of dt, and the step
// count is not always duration / dt (see tests/data/README.md).
#pragma once

#include <cmath>
#include <cstdint>

namespace bouncecheck {

// Steps the document's loop takes for (dt, duration). O(steps): it replays the
// accumulation of t, because no closed form reproduces its rounding.
std::int64_t document_step_count(double dt, double duration);

// Iterates the document's sample times t_0 = 0, t_{n+1} = t_n + dt.
class DocumentClock {
public:
    DocumentClock(double dt, double duration) : dt_(dt), duration_(duration) {}
    double t() const { return t_; }
    // True while the loop would take another step from the current t.
    bool running() const { return std::abs(t_) < std::abs(duration_); }
    void advance() { t_ = t_ + dt_; }

private:
    double dt_;
    double duration_;
    double t_ = 0.0;
};

// The states a run still takes after the one at `clock` (the document's loop
// adds dt while |t| < |duration|). O(steps): it replays the additions.
inline std::int64_t remaining_steps(DocumentClock clock) {
    std::int64_t n = 0;
    for (; clock.running(); clock.advance()) ++n;
    return n;
}

}  // namespace bouncecheck
