// The Box2D 2.4.1 adapter's tunable settings, exposed so that the tests can
// restore one of Box2D's defaults at a time and measure what it does (every
// field's default here is the value the adapter runs with; the comment gives
// Box2D's own default, the trap).
#pragma once

#include "engines/engine.h"

#include <memory>
#include <vector>

namespace bouncecheck::box2d {

// What the registry reports without loading the adapter's module.
inline constexpr EngineIdentity kIdentity{
    "box2d", "Box2D 2.4.1 (2D, float): dynamic circle in four static boxes, scaled so the ball is 1 m",
    890};

struct Tuning {
    // Engine length per scenario length; 0 means 1 / radius (the ball is 1 m in
    // the engine). Box2D default: none (1, the 5 cm ball against 5 mm of slop).
    double length_scale = 0.0;
    // b2FixtureDef::restitutionThreshold (engine m/s) on ball and walls, and per
    // contact. Box2D default 1 m/s: impacts slower than that do not bounce.
    float restitution_threshold = 0.0f;
    // Set friction and restitution per contact in PreSolve (exact mu and alpha
    // whatever b2MixFriction / b2MixRestitution make of the fixture values).
    bool override_mix = true;
    // Wall fixture friction and restitution; negative means mu and alpha (the
    // adapter's choice). Box2D defaults: friction 0.2, restitution 0.
    float wall_friction = -1.0f;
    float wall_restitution = -1.0f;
    // Place the walls' faces b2_polygonRadius outside the room so the skinned
    // surface is the room's surface. Box2D default: the skin sits inside.
    bool compensate_skin = true;
    // b2World::SetAllowSleeping and b2BodyDef::allowSleep. Box2D default: true.
    bool allow_sleep = false;
    // b2World::SetContinuousPhysics (time of impact against static walls). Default true.
    bool continuous = true;
    // b2World::Step iterations; Box2D's testbed uses 8 and 3.
    int velocity_iterations = 8;
    int position_iterations = 3;
    // b2World::SetWarmStarting. Default true.
    bool warm_starting = true;
};

// The world the adapter builds with `tuning` (the bench steps it bare to
// measure the shared loop's overhead), appending the settings used.
std::unique_ptr<EngineWorld> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                         std::vector<Setting>& settings);

// The "box2d" simulator with non-default tuning (tests only).
std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning);

}  // namespace bouncecheck::box2d

namespace bouncecheck {

// The registered "box2d" simulator (registry/registry.cpp), with the adapter's chosen tuning.
std::unique_ptr<const Simulator> make_box2d_simulator();

}  // namespace bouncecheck
