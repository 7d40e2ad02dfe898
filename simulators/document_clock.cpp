#include "simulators/document_clock.h"

namespace bouncecheck {

std::int64_t document_step_count(double dt, double duration) {
    std::int64_t steps = 0;
    for (DocumentClock clock(dt, duration); clock.running(); clock.advance()) ++steps;
    return steps;
}

}  // namespace bouncecheck
