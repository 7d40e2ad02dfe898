// Bullet 3.24 (double precision) adapter.
//
// Exposes the tuning and a steppable world so that the tests can restore any
// trap's default and measure what it does; the registry only uses
// make_bullet_simulator(). Free of Bullet headers: the tests include it
// without Bullet's include paths or BT_USE_DOUBLE_PRECISION.
#pragma once

#include "engines/engine.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace bouncecheck::bullet {

// What the registry reports without loading the adapter's module.
inline constexpr EngineIdentity kIdentity{
    "bullet", "Bullet 3.24 (double): sphere in six static planes, sequential-impulse solver, one step of dt",
    1490};

// How each step is asked of btDiscreteDynamicsWorld::stepSimulation.
enum class Stepping {
    single_step,     // stepSimulation(dt, 0): exactly one internal step of dt (chosen)
    default_args,    // stepSimulation(dt): fixed 1/60 s substeps, at most one per call (Bullet's default)
};

// Every setting that changes the answer. chosen() is what the adapter uses;
// the tests change one field at a time to put a trap's default back.
struct Tuning {
    Stepping stepping = Stepping::single_step;

    // btContactSolverInfo. Bullet's defaults in the comments.
    double restitution_velocity_threshold = 0.0;  // 0.2 m/s: no bounce below this incoming speed
    bool split_impulse = true;                    // true
    // Penetrations deeper than this (distance < threshold, i.e. more negative)
    // go to the split (position-only) impulse, shallower ones are corrected by
    // Baumgarte in the velocity. Bullet: -0.04. Chosen: +huge, so every
    // penetration (and every speculative gap) is split.
    double split_impulse_penetration_threshold = 1e30;
    double erp2 = 1.0;                  // 0.2: fraction of a penetration removed per step (contacts)
    double erp = 0.2;                   // 0.2: non-contact constraints only (none here)
    double global_cfm = 0.0;            // 0
    double linear_slop = 0.0;           // 0
    int solver_iterations = 10;         // 10
    bool warm_starting = false;         // true (factor 0.85)

    // Contact-breaking threshold of every ball-wall manifold: a contact point
    // is made (and kept) while the ball is closer than this to the wall. A
    // negative value keeps Bullet's own (0.02 x the sphere's angular motion
    // disc = 1.73 mm for r = 5 cm).
    double contact_breaking_threshold = 1e-9;

    bool disable_deactivation = true;   // false: the ball sleeps after 2 s below 0.8 m/s
    double ccd_motion_threshold = 0.0;  // 0: CCD off (Bullet's default)

    // Material combine: Bullet multiplies the two bodies' restitutions and
    // frictions. true: walls 1, ball alpha / mu, so the products are alpha / mu.
    // false: the ball still alpha / mu, the walls left at Bullet's defaults
    // (restitution 0, friction 0.5): products 0 and mu / 2.
    bool unit_wall_materials = true;

    // false: the world keeps Bullet's default gravity (0, -10, 0).
    bool set_gravity = true;

    static Tuning chosen() { return Tuning{}; }
};

// What the adapter saw, for the tests.
struct Stats {
    std::int64_t steps = 0;
    std::int64_t new_wall_contacts = 0;   // ball-wall manifolds that gained points (per_contact applies beta here)
    std::int64_t touching_steps = 0;      // steps with at least one ball-wall manifold point
};

// A built Bullet world, steppable one engine step at a time.
class World : public EngineWorld {
public:
    // Engine-frame centre and velocity (2D: the x-z plane, y the locked axis).
    virtual Vec3 engine_position() const = 0;
    virtual Vec3 engine_velocity() const = 0;
    virtual Vec3 engine_angular_velocity() const = 0;
    virtual Vec3 engine_gravity() const = 0;  // the ball body's gravity as Bullet uses it
    virtual bool ball_active() const = 0;     // false once Bullet put the ball to sleep
    virtual const Stats& stats() const = 0;
};

// Builds the world for `s` with `tuning`, appending the settings used.
std::unique_ptr<World> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                   std::vector<Setting>& settings);

// The registered simulator is make_bullet_simulator() (tuning chosen()); this one
// runs any tuning through the same shared run() (name "bullet" as well).
std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning);

}  // namespace bouncecheck::bullet

namespace bouncecheck {

// The registered "bullet" simulator (registry/registry.cpp), with the adapter's chosen tuning.
std::unique_ptr<const Simulator> make_bullet_simulator();

}  // namespace bouncecheck
