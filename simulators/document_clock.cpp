#include "simulators/document_clock.h"

#include <limits>

namespace bouncecheck {

std::int64_t document_step_count(double dt, double duration) { return DocumentClock(dt, duration).remaining_steps(); }

std::int64_t DocumentClock::remaining_steps() const {
    // With t >= 0 and dt > 0 (every loaded scenario), |t| < |duration| is t < |duration|.
    if (t_ >= 0 && dt_ > 0)
        return additions_to_reach(t_, dt_, std::abs(duration_), std::numeric_limits<std::int64_t>::max())
            .value_or(std::numeric_limits<std::int64_t>::max());
    std::int64_t n = 0;
    for (DocumentClock clock = *this; clock.running(); clock.advance()) ++n;
    return n;
}

}  // namespace bouncecheck
