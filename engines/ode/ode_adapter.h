// ODE 0.16 (Open Dynamics Engine, double precision) adapter.
//
// Exposes the tuning and the world so that the tests can restore any trap's
// default and measure what it does; the registry only uses make_ode_simulator().
// Free of ODE headers: the tests include it without ODE's include paths.
#pragma once

#include "engines/engine.h"

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

namespace bouncecheck::ode {

// What the registry reports without loading the adapter's module.
inline constexpr EngineIdentity kIdentity{
    "ode", "Open Dynamics Engine 0.16 (double): sphere vs static planes, contact joints with bounce, dWorldStep",
    990};

enum class Stepper {
    world_step,  // dWorldStep: Dantzig LCP, constraints solved exactly (chosen)
    quick_step,  // dWorldQuickStep: projected Gauss-Seidel/SOR, iterative
};

// Every setting that changes the answer. chosen() is what the adapter uses;
// the tests change one field at a time to put a trap's default back.
struct Tuning {
    Stepper stepper = Stepper::world_step;
    int quick_step_iterations = 20;  // ODE's default, used only by quick_step

    // World-wide constraint parameters (ODE defaults: ERP 0.2, CFM 1e-5).
    double world_erp = 0.2;  // joints only (the planar joint); contacts use contact_erp
    double world_cfm = 0.0;

    // Contact softness: dContactSoftERP / dContactSoftCFM in surface.mode. When
    // a flag is off the contact takes the world's value.
    bool contact_soft_erp = true;
    double contact_erp = 0.0;
    bool contact_soft_cfm = true;
    double contact_cfm = 0.0;

    double bounce_vel = 0.0;          // surface.bounce_vel: no bounce below this incoming speed
    double surface_layer = 0.0;       // dWorldSetContactSurfaceLayer
    double max_correcting_vel = 0.0;  // dWorldSetContactMaxCorrectingVel (ODE default: infinity)
    bool auto_disable = false;        // dWorldSetAutoDisableFlag

    bool approx1 = true;          // dContactApprox1: friction bound = mu x normal force (else mu is a force in N)
    bool align_friction = true;   // first friction direction along the contact's slip (else ODE's arbitrary pyramid)
    std::optional<double> mu_override;  // test hook: replaces options.friction (e.g. infinity, as many samples)
    int max_contacts = 4;         // contact points asked of dCollide per ball-wall pair
    double ball_mass = 1.0;       // kg; only the CFM terms depend on it

    static Tuning chosen() { return Tuning{}; }
};

// What the near callback saw, for the tests.
struct Stats {
    std::int64_t pairs_touching = 0;   // ball-wall pairs with at least one contact, summed over steps
    int max_contacts_per_pair = 0;     // largest dCollide count for one ball-wall pair
    std::int64_t contact_joints = 0;   // contact joints created, summed over steps
    std::int64_t new_contacts = 0;     // ball-wall contacts that started (per_contact applies beta here)
};

class World : public EngineWorld {
public:
    // Raw engine-frame centre (x, y, z in ODE's axes), e.g. to check the planar joint.
    virtual Vec3 engine_position() const = 0;
    virtual Vec3 engine_angular_velocity() const = 0;
    virtual const Stats& stats() const = 0;
};

// The world the adapter builds, with `tuning` instead of chosen().
std::unique_ptr<World> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                   std::vector<Setting>& settings);

// A simulator named "ode" that runs with `tuning` (the registry's uses chosen()).
std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning);

}  // namespace bouncecheck::ode

namespace bouncecheck {

// The registered "ode" simulator (registry/registry.cpp), with the adapter's chosen tuning.
std::unique_ptr<const Simulator> make_ode_simulator();

}  // namespace bouncecheck
