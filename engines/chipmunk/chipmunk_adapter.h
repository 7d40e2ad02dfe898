// The Chipmunk2D 7.0.3 adapter's tunable settings, exposed so that the tests
// can restore one of Chipmunk's defaults at a time and measure what it does
// (every field's default here is the value the adapter runs with; the comment
// gives Chipmunk's own default, the trap).
#pragma once

#include "engines/engine.h"

#include <limits>
#include <memory>
#include <vector>

namespace bouncecheck::chipmunk {

// What the registry reports without loading the adapter's module.
inline constexpr EngineIdentity kIdentity{
    "chipmunk", "Chipmunk2D 7.0.3 (2D, double): dynamic circle in four static thick segments",
    280};

// Where the per-contact hook scales the tangential velocity by beta.
enum class PerContactCallback {
    begin,      // cpCollisionHandler::beginFunc: once, the step a contact starts
    pre_solve,  // preSolveFunc: every step the shapes overlap (beta compounds over a contact)
};

struct Tuning {
    // cpSpace collisionSlop, in metres (the space's units are the scenario's:
    // no length scale). Chipmunk default 0.1: overlap up to 0.1 is never
    // pushed out, two radii of the seed's 5 cm ball.
    double collision_slop = 0.0;
    // cpSpace collisionBias: the fraction of an overlap left after one second
    // of position correction (1 - bias^dt of it is removed per step, through
    // the bias velocity: position only). Chipmunk default pow(1 - 0.1, 60) =
    // 0.0018 (10% per 1/60 s), kept: 0 (all of it in one step) makes a ball
    // at rest hop, and beta damps a slide at every hop. The literal is
    // cpSpaceInit's cpfpow(1.0f - 0.1f, 60.0f), 0.9f being 0.89999998.
    double collision_bias = 0.0017970074436457143;
    // cpSpace iterations of the impulse solver. Chipmunk default 10.
    int iterations = 10;
    // cpSpace collisionPersistence: steps an arbiter (and its accumulated
    // impulse) is kept after the shapes separate. Chipmunk default 3.
    unsigned collision_persistence = 3;
    // cpSpace damping: velocity kept after one second. Chipmunk default 1 (none).
    double damping = 1.0;
    // cpSpace sleepTimeThreshold. Chipmunk default INFINITY (sleeping off).
    double sleep_time_threshold = std::numeric_limits<double>::infinity();
    // Wall shapes' elasticity and friction. Chipmunk combines by product
    // (e = e_ball e_wall, u = u_ball u_wall); a new shape has e = 0 and u = 0,
    // which makes every contact dead and frictionless whatever the ball has.
    double wall_elasticity = 1.0;
    double wall_friction = 1.0;
    // Wall segments' radius, metres; 0 or less means half the room's larger
    // side (a thick wall). Chipmunk's cpSegmentShapeNew takes it from the caller.
    double wall_radius = 0.0;
    // Put each segment's line wall_radius outside the room, so that the
    // rounded surface is the wall. Not doing so (a segment on the wall's line)
    // puts the surface wall_radius inside the room.
    bool compensate_wall_radius = true;
    // Per-contact mode: which collision callback applies beta.
    PerContactCallback per_contact_callback = PerContactCallback::begin;
};

// The world the adapter builds with `tuning` (the bench steps it bare to
// measure the shared loop's overhead), appending the settings used.
std::unique_ptr<EngineWorld> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                         std::vector<Setting>& settings);

// The "chipmunk" simulator with non-default tuning (tests only).
std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning);

}  // namespace bouncecheck::chipmunk

namespace bouncecheck {

// The registered "chipmunk" simulator (registry/registry.cpp), with the adapter's chosen tuning.
std::unique_ptr<const Simulator> make_chipmunk_simulator();

}  // namespace bouncecheck
