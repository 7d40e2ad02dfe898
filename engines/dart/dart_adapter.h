// The DART 6.12 adapter's tunable settings, exposed so that the tests can
// restore one of DART's defaults at a time and measure what it does (every
// field's default here is the value the adapter runs with; the comment gives
// DART's own default, the trap). Free of DART headers: the tests include it
// without DART's include path.
#pragma once

#include "engines/engine.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

// Not bouncecheck::dart: inside namespace bouncecheck that name would hide
// DART's own ::dart.
namespace bouncecheck::dartsim {

// What the registry reports without loading the adapter's module.
inline constexpr EngineIdentity kIdentity{
    "dart", "DART 6.12 (double): sphere in six fixed boxes, DARTCollisionDetector, Dantzig LCP, length scale "
                 "from dt and g",
    4450};

enum class Detector {
    dart,            // DARTCollisionDetector: analytic sphere-box (chosen)
    fcl_primitive,   // FCL with FCLCollisionDetector::PRIMITIVE (analytic sphere)
    fcl_mesh,        // FCL with MESH: the sphere tessellated (DART's default detector and mode)
};

enum class LcpSolver { dantzig, pgs };  // BoxedLcpConstraintSolver's primary solver

// DART's restitution rule, compile-time constants of ContactConstraint.cpp
// (6.12): a contact bounces only when e |v_n| > 0.1 (model units per
// second), and never faster than 100.
inline constexpr double kBouncingVelocityThreshold = 0.1;
inline constexpr double kMaxBouncingVelocity = 100.0;

struct Tuning {
    Detector detector = Detector::dart;  // DART: FCL, MESH

    // Length scale (UnitScale::length); <= 0: the rule (length_scale_for).
    // DART: 1 (it has no units; its constants are tuned for metres).
    double length_scale = 0;
    // The rule's margin: the resting micro-bounce's speed e |g| dt / (1 - e)
    // (model units) is kept below the restitution threshold by this factor.
    double rest_margin = 2;
    // The rule's upper bound (centimetres): the largest scale measured.
    double max_length_scale = 100;

    // Wall shapes' restitution. DART combines ball x wall; its default is 0:
    // walls left unset never bounce anything.
    double wall_restitution = 1.0;

    // ContactConstraint's penetration correction (process-wide statics: see
    // the "threads" setting), model units. The defaults of DART
    // 6.12 (#define DART_ERP 0.01, DART_MAX_ERV 1e-3, DART_ERROR_ALLOWANCE 0,
    // DART_CFM 1e-5), set explicitly at every step.
    double error_reduction = 0.01;
    double max_error_reduction_velocity = 1e-3;
    double error_allowance = 0.0;
    double constraint_force_mixing = 1e-5;

    // BoxedLcpConstraintSolver: primary Dantzig, PGS as the fallback
    // (DART's default). pgs_iterations: PgsBoxedLcpSolver's (DART: 30).
    LcpSolver lcp = LcpSolver::dantzig;
    int pgs_iterations = 30;

    // CollisionOption::maxNumContacts (DART: 1000). One ball touches at most three walls.
    std::size_t max_contacts = 1000;

    // Friction mode: before every step, point the ball's first friction
    // direction (world frame) along its velocity, so that the friction
    // pyramid's edge lies along the slip and a sliding contact is Coulomb's.
    // DART: a fixed basis (x and y on a floor; each bounded by mu N on its
    // own), so a diagonal slip takes up to sqrt(2) mu N and turns towards 45 degrees.
    bool friction_along_slip = true;

    bool set_timestep = true;  // false: DART's 0.001 s whatever dt is
    bool set_gravity = true;   // false: DART's (0, 0, -9.81)

    // Per-contact beta applied before the step that finds the contact (from
    // a collision query at the step's starting position, which the step's
    // own detection sees too), so the step moves the ball with the scaled
    // velocity; false: after that step.
    bool beta_before_step = true;
};

// The length scale the adapter runs `s` at with `t` (the rule; or t.length_scale).
double length_scale_for(const Scenario& s, const Tuning& t);

struct Stats {
    std::int64_t steps = 0;
    std::int64_t new_wall_contacts = 0;  // ball-wall contacts that started (per-contact mode)
    std::int64_t beta_applied = 0;       // of them, counted by the law (moves_into_wall)
    std::size_t max_contacts = 0;        // most contacts in one step's collision result
};

class World : public EngineWorld {
public:
    virtual const Stats& stats() const = 0;
    virtual double length_scale() const = 0;
    // Angular velocity of the ball (rad/s, world frame): a tessellated sphere spins.
    virtual double spin() const = 0;
};

std::unique_ptr<World> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                   std::vector<Setting>& settings);

// The "dart" simulator with non-default tuning (tests only).
std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning);

}  // namespace bouncecheck::dartsim

namespace bouncecheck {

// The registered "dart" simulator (registry/registry.cpp), with the adapter's chosen tuning.
std::unique_ptr<const Simulator> make_dart_simulator();

}  // namespace bouncecheck
