// MuJoCo 2.2.2 adapter (double precision, 3D, and 2D on slide joints in the
// x-z plane).
//
// Exposes the tuning and a steppable world so that the tests can restore any
// trap's default and measure what it does; the registry only uses
// make_mujoco_simulator(). Free of MuJoCo headers: the tests include it
// without MuJoCo's include path.
#pragma once

#include "engines/engine.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace bouncecheck::mujoco {

// What the registry reports without loading the adapter's module.
inline constexpr EngineIdentity kIdentity{
    "mujoco", "MuJoCo 2.2.2 (double): sphere on slide joints in six planes, one-step damper contacts, Euler",
    1390};

// How a ball-wall contact bounces. MuJoCo has no restitution coefficient: a
// contact row's reference acceleration is aref = -b v - k x (solref in the
// direct format (-k, -b), x the penetration, v the normal velocity), reached
// through the impedance d (solimp): a = (1 - d) a_free + d aref.
enum class ContactLaw {
    // b dt = 1 + alpha: the step that finds the ball inside a wall turns its
    // normal velocity from -u to alpha u, whatever the depth; the next step
    // carries it out (or, if it started deeper than alpha u dt, the one after,
    // the row inactive because it would pull). A weak anchor spring
    // (damper_anchor) holds a resting ball up. (chosen)
    one_step_damper,
    // A spring-damper lasting several steps: k from the stiffness rule below,
    // b derived from alpha and corrected for the step (contact_parameters()).
    // Not chosen: its restitution depends on where within a step the ball
    // crosses the wall (tests/test_mujoco.cpp, MujocoSpring).
    spring,
    // MuJoCo's default solref (0.02, 1): time constant 0.02 s, critically damped.
    engine_default,
};

enum class Integrator { euler, rk4, implicit };  // mjINT_*; MuJoCo's default: Euler
enum class Cone { pyramidal, elliptic };          // mjCONE_*; MuJoCo's default: pyramidal

// Every setting that changes the answer. chosen() is what the adapter uses;
// the tests change one field at a time to put a trap's default back. MuJoCo's
// own defaults in the comments.
struct Tuning {
    ContactLaw law = ContactLaw::one_step_damper;  // MuJoCo: solref (0.02, 1)

    // The damper's anchor spring: k dt^2 = damper_anchor (1 - alpha). The
    // impedance lets 1 - d' = 1e-4 of gravity through a contact, so a resting
    // ball on a pure damper sinks at 1e-4 g dt / (1 + alpha) per second,
    // forever; the spring holds it at 1e-4 g dt^2 / (k dt^2) below the surface
    // (g dt^2 / (1 - alpha) with 1e-4), reached with a time constant of
    // (1 + alpha) dt / (k dt^2). It moves a bounce's restitution by
    // k dt^2 (phi - 1/2), phi the depth found over u dt (the damping is set
    // for the mean). Scaled by 1 - alpha: a ball that rests has alpha < 1,
    // and at alpha = 1 nothing damps that noise: a constant 1e-4 made
    // stress/elastic's energy drift 0.0108 J/kg (tolerance 0.0072), 1e-5 0.0057.
    double damper_anchor = 1e-4;

    // Stiffness rule of ContactLaw::spring: omega = sqrt(k) is the largest of
    // pi / (spring_steps dt) (the contact lasts spring_steps steps) and
    // v_max / (spring_penetration r) (the fastest impact the scenario allows
    // sinks at most that fraction of r), but never above pi / (spring_min_steps dt).
    double spring_steps = 12;
    double spring_min_steps = 3;
    double spring_penetration = 0.04;
    double spring_stiffness = 0;        // > 0: this k (1/s^2) instead of the rule (the early probes' 1000)
    bool spring_correct_damping = true; // false: b from the continuous formula alone

    // solimp (dmin, dmax, width, midpoint, power). MuJoCo: (0.9, 0.95, 0.001, 0.5, 2).
    std::array<double, 5> solimp{0.9999, 0.9999, 0.001, 0.5, 2};
    // Divide solref by impedance_factor (see ContactParameters) so the ball
    // feels exactly k and b; false leaves them as an ideal (d = 1) constraint's.
    bool correct_for_impedance = true;

    // Wall geoms' sliding friction; < 0: the ball's (mu). MuJoCo: 1 (and a
    // contact takes the larger of the two geoms').
    double wall_friction = -1;
    // Contact dimensionality; 0: the adapter's (1 when mu = 0, else 3). MuJoCo: 3.
    int condim = 0;
    Cone cone = Cone::elliptic;        // MuJoCo: pyramidal
    double impratio = 1;               // MuJoCo: 1
    double margin = 0, gap = 0;        // MuJoCo: 0, 0

    bool set_timestep = true;          // false: MuJoCo's 0.002 s whatever dt is
    bool set_gravity = true;           // false: MuJoCo's (0, 0, -9.81)
    Integrator integrator = Integrator::euler;
    double ball_mass = 1;              // kg; <= 0: MuJoCo's geom density 1000 kg/m^3

    // mj_step checks qpos, qvel and qacc and, on a NaN or a value beyond 1e10,
    // resets mjData to the model's initial state and goes on (a warning
    // only). true: any MuJoCo warning (such a reset, a full contact or
    // constraint buffer, ...) fails the run with its text.
    bool fail_on_warning = true;

    // Per-contact beta: applied between mj_step1 and mj_step2 (the step that
    // finds the contact moves the ball with the scaled velocity), or after
    // mj_step (that step moves it with the unscaled one).
    bool beta_in_split_step = true;

    static Tuning chosen() { return Tuning{}; }
};

// The contact's solref (direct format: stiffness k, damping b, per unit mass),
// as build_world sets it for `s` with `t`, and how it was chosen.
struct ContactParameters {
    double stiffness = 0;        // k (1/s^2); the damper: its anchor / dt^2
    double damping = 0;          // b (1/s), the value MuJoCo gets
    double damping_derived = 0;  // b from alpha alone (ideal constraint; continuous formula for the spring)
    // What the ball feels per unit of solref: MuJoCo scales solref by 1 / dmax
    // (damping) and 1 / dmax^2 (stiffness), the impedance d and the regulariser
    // R = (1 - d) / d A~ (A~ its diagonal approximation of the contact's
    // inverse mass A) give a = (1 - d') a_free + d' aref with d' = A / (A + R):
    // the factor is d' / d = 1 / (d + (1 - d) A~ / A). A~ / A = 1 in 3D, 2/3 in
    // 2D (the mean of the ball's translational inverse inertias over three
    // axes, one of them locked). Exact for a flat impedance (dmin = dmax).
    double impedance_factor = 1;
    double omega_dt = 0;         // sqrt(k) dt
    double v_max = 0;            // fastest speed the ball can reach (energy bound)
    std::string rule;            // which bound chose k (spring)
};
ContactParameters contact_parameters(const Scenario& s, const Tuning& t);

// The spring law's restitution predicted by replaying MuJoCo's step for one
// contact without gravity: semi-implicit Euler (v += a dt, then x += v dt),
// the contact found at the start of a step that begins inside the wall, and
// a = max(0, -b v - k x) (a contact never pulls; k, b as the ball feels
// them, i.e. the solref values times impedance_factor). `mean` averages
// over where within a step the ball crosses the wall (64 phases); lowest and
// highest are the extremes.
struct SpringRestitution {
    double mean = 0, lowest = 0, highest = 0;
    int steps = 0;  // steps in contact at the middle phase
};
SpringRestitution spring_restitution(double omega_dt, double damping_dt);

// What the adapter saw, for the tests (contacts: per-contact mode only).
struct Stats {
    std::int64_t steps = 0;
    std::int64_t new_wall_contacts = 0;  // ball-wall contacts that started (per_contact applies beta here)
    std::int64_t beta_applied = 0;       // of them, counted by the law (moves_into_wall)
    std::int64_t touching_steps = 0;     // steps with at least one ball-wall contact
    int max_contacts = 0;                // largest d->ncon seen
};

// A built MuJoCo world, steppable one engine step at a time.
class World : public EngineWorld {
public:
    // Engine-frame (MuJoCo x, y, z) centre and velocity; 2D runs in the x-z plane.
    virtual Vec3 engine_position() const = 0;
    virtual Vec3 engine_velocity() const = 0;
    virtual Vec3 engine_gravity() const = 0;
    virtual double engine_timestep() const = 0;
    virtual double ball_mass() const = 0;
    virtual int rotational_dofs() const = 0;  // 0 locked, 1 (2D hinge) or 3 (3D ball joint)
    virtual const Stats& stats() const = 0;
    virtual const std::string& model_xml() const = 0;  // the MJCF compiled for this world
};

// Builds the world for `s` with `tuning`, appending the settings used.
std::unique_ptr<World> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                   std::vector<Setting>& settings);

// The registered simulator is make_mujoco_simulator() (tuning chosen()); this
// one runs any tuning through the same shared run() (name "mujoco" as well).
std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning);

}  // namespace bouncecheck::mujoco

namespace bouncecheck {

// The registered "mujoco" simulator (registry/registry.cpp), with the adapter's chosen tuning.
std::unique_ptr<const Simulator> make_mujoco_simulator();

}  // namespace bouncecheck
