// Test helper: a scenario built in code, every field given (no engine
// tables, no thresholds).
#pragma once

#include "scenarios/scenario.h"

namespace bouncecheck::test {

inline Scenario make_scenario(int dim, Vec3 room, double radius, Vec3 position, Vec3 velocity, Vec3 gravity,
                              double alpha, double beta, double duration, double dt = 0.03) {
    Scenario s;
    s.name = "test";
    s.dim = dim;
    s.room = room;
    s.radius = radius;
    s.position = position;
    s.velocity = velocity;
    s.gravity = gravity;
    s.alpha = alpha;
    s.beta = beta;
    s.dt = dt;
    s.duration = duration;
    return s;
}

}  // namespace bouncecheck::test
