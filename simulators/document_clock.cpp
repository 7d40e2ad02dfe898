#include "simulators/document_clock.h"

#include <limits>

namespace bouncecheck {

std::int64_t document_step_count(double dt, double duration) { return DocumentClock(dt, duration).remaining_steps(); }

std::int64_t DocumentClock::remaining_steps() const {
    // With t >= 0 and dt > 0 (every loaded scenario), |t| < |duration| is t < |duration|.
    if (t_ >= 0 && dt_ > 0)
        return additions_to_reach(t_, dt_, std::abs(duration_), std::numeric_limits<std::int64_t>::max())
            .value_or(std::numeric_limits<std::int64_t>::max());
    // Otherwise one addition at a time (a negative dt: the loop counts |t|
    // up). With dt = 0, t stops moving and the loop never ends.
    std::int64_t n = 0;
    for (DocumentClock clock = *this; clock.running(); ++n) {
        const double before = clock.t();
        clock.advance();
        if (clock.t() == before) return std::numeric_limits<std::int64_t>::max();
    }
    return n;
}

}  // namespace bouncecheck
