#include "simulators/stream_contacts.h"

#include <algorithm>

namespace bouncecheck {

StreamContactDetector::StreamContactDetector(const Scenario& s)
    : radius_(s.radius), room_(s.room), dt_(s.dt),
      // A resting engine ball jitters at the wall with speeds of the order of
      // what gravity adds in a step; a hundredth of that is not an impact.
      min_impact_speed_(0.01 * s.gravity.norm() * s.dt + 1e-12) {}

ContactMask StreamContactDetector::contacts_of(const State& previous, const State& current) const {
    ContactMask mask;
    for (int i = 0; i < 3; ++i) {
        const bool reversed_down = previous.v[i] < -min_impact_speed_ && current.v[i] >= 0;
        const bool reversed_up = previous.v[i] > min_impact_speed_ && current.v[i] <= 0;
        // Near enough to have touched during the step: one step of travel at
        // the incoming speed, plus a tenth of the radius for contact margins,
        // from the nearer of the two samples.
        const double reach = std::abs(previous.v[i]) * dt_ + 0.1 * radius_;
        const double low = std::min(previous.p[i], current.p[i]), high = std::max(previous.p[i], current.p[i]);
        if (reversed_down && low - radius_ <= reach) mask.lower |= 1u << i;
        if (reversed_up && room_[i] - radius_ - high <= reach) mask.upper |= 1u << i;
    }
    return mask;
}

}  // namespace bouncecheck
