// Contacts seen in a stream of states, for a simulator that does not
// report them itself: the engines, whose contact callbacks differ, and
// external programs and imported trajectories, which report states only.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/state.h"

#include <cmath>

namespace bouncecheck {

// Contacts seen in a stream of states: a wall contact is counted when the
// normal velocity component turns from moving into the wall (faster than a
// noise floor of 1% of |g| dt) to not moving into it, while the ball is
// within `reach` of touching that wall at either sample. `reach` allows for
// the engine's contact margin and one step of travel (an engine with
// speculative contacts turns the ball up to a step before the wall).
class StreamContactDetector {
public:
    explicit StreamContactDetector(const Scenario& s);
    // Every step, inline: one branch-free screen for a reversal on any axis
    // (on most steps there is none, and the distance test is not needed): a
    // component that was faster than the noise floor and now has the other
    // sign or is zero. The screen may pass a step with no contact (a product
    // that underflows), never miss one; contacts_of decides. An unused axis
    // has v = 0, which never passes.
    // D: the axes to look at (3 is always right; 2 skips z in a 2D scene).
    template <int D = 3>
    ContactMask detect(const State& previous, const State& current) const {
        bool reversed = false;
        for (int i = 0; i < D; ++i)
            reversed |= (previous.v[i] * current.v[i] <= 0) & (std::abs(previous.v[i]) > min_impact_speed_);
        return reversed ? contacts_of(previous, current) : ContactMask{};
    }

private:
    ContactMask contacts_of(const State& previous, const State& current) const;

    double radius_;
    Vec3 room_;
    double dt_;
    double min_impact_speed_;
};

}  // namespace bouncecheck
