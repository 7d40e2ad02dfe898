// The Siconos 4.4 adapters: "siconos" (time-stepping: TimeStepping +
// MoreauJeanOSI + LCP, or FrictionContact with Coulomb friction) and
// "siconos-ed" (event-driven: EventDriven + LsodarOSI, contacts resolved at
// their exact instants).
//
// Exposes the tuning and a steppable world so that the tests can restore one
// of Siconos's defaults at a time and measure what it does (every field's
// default here is the value the adapter runs with; the comment gives
// Siconos's own default). Free of Siconos headers, which do not compile as
// C++20: the Siconos side is siconos_model.{h,cpp}, in C++17.
#pragma once

#include "engines/engine.h"

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace bouncecheck::siconos {

// What the registry reports without loading the adapters' module.
inline constexpr EngineIdentity kTimeSteppingIdentity{
    "siconos",
    "Siconos 4.4 time-stepping (TimeStepping + MoreauJeanOSI theta 0.5, LCP / FrictionContact), NewtonImpactNSL",
    7000};
inline constexpr EngineIdentity kEventDrivenIdentity{
    "siconos-ed",
    "Siconos 4.4 event-driven (EventDriven + LsodarOSI): impacts at their exact instants, NewtonImpactNSL", 7500};

struct Tuning {
    // --- MoreauJeanOSI (siconos)
    // theta of the theta-method: q+ = q + h ((1 - theta) v + theta v+).
    // Siconos default 0.5 (MoreauJeanOSI(theta = 0.5)), kept.
    double theta = 0.5;
    // gamma: NaN leaves Siconos's "not used" (useGamma false); the activation
    // prediction y + gamma h y_dot then uses 1/2 anyway. Siconos default NaN.
    double gamma = std::numeric_limits<double>::quiet_NaN();
    // A wall's constraint is active for the step when y + h/2 y_dot <= this.
    // Siconos default 0.
    double activation_threshold = 0.0;
    // useGammaForRelation. Siconos default false.
    bool use_gamma_for_relation = false;

    // --- the nonsmooth problems' numerics SolverOptions (both simulators)
    // false: numerics' defaults for the solver (Lemke: tolerance 1e-6,
    // 10000 iterations; 2D/3D friction NSGS: tolerance 1e-4, 1000
    // iterations). Measured: neither changes a one-contact result (Lemke
    // pivots exactly; NSGS solves one contact in one sweep); set tight so
    // that coupled contacts (a corner) are solved to round-off too.
    bool set_solver_options = true;
    double solver_tolerance = 1e-12;
    int solver_max_iterations = 1000;

    // --- LsodarOSI and EventDriven (siconos-ed)
    // Lsodar's scalar rtol and atol (itol 1), written into the arrays Lsodar
    // reads (LsodarOSI::setTol with scalars writes rtol into atol). Siconos
    // defaults 10 eps and 100 eps = 2.2e-14 (LsodarOSI.hpp). rtol kept; atol
    // 1e-16 (half an ulp of a 1 m coordinate): with 2.2e-14 the Zeno tail's
    // hops lower than ~1e-13 m are integrated with errors of their own size,
    // end early, and seed-3d's ball comes to rest 8.0e-7 m short of exact's.
    double lsodar_rtol = 10 * std::numeric_limits<double>::epsilon();
    double lsodar_atol = 1e-16;
    // EventDriven::_TOL_ED (a static of the library, set by every world): a
    // gap within it is a contact, a post-impact normal speed within it
    // closes the contact (the ball rests: indexSet 2). Siconos default
    // 1000 x 10 eps = 2.2e-12, kept.
    double event_tolerance = 1e4 * std::numeric_limits<double>::epsilon();
    // Raise event_tolerance to the deepest gap Lsodar's root finder can
    // return, |v|max x 100 eps x 2 T (siconos_adapter.cpp, event_tolerance):
    // below it Siconos throws at a root it located itself. Siconos has no
    // such rule; it leaves the seeds at 2.2e-12.
    bool size_event_tolerance = true;

    // --- per-contact hook
    // siconos: the contact step's position update q+ = q + h ((1 - theta) v +
    // theta v+) is redone with the scaled v+ (as if beta were applied between
    // the LCP and the state update). false: beta after the step, the step's
    // travel unscaled.
    bool correct_position = true;
    // siconos-ed: when an impact closes a contact (the post-impact normal
    // speed is within event_tolerance, Siconos puts the ball at rest on the
    // wall), the velocity is set to the law's limit, as exact does: the
    // infinitely many remaining contacts scale the tangential velocity by
    // beta^inf = 0 (beta < 1), and the normal speed Siconos leaves (up to
    // event_tolerance, 1.8e-12 m/s in seed-3d: the resting ball rises at that
    // speed for good) is 0. false: both are left as Siconos has them.
    bool zeno_limit = true;
    // siconos-ed, with zeno_limit (both tangential models: in friction mode,
    // mu = 0, only the normal speed is set to 0): an impact also ends the accumulation when
    // the law's remaining accumulation time 2 alpha u / (|g_n| (1 - alpha))
    // is below this (s): the ball then misses at most |v| x this of travel
    // (1e-8 m at 1 m/s). Siconos alone closes only below _TOL_ED m/s, which
    // its hops never reach under stronger gravity (g = 1 m/s^2, alpha 0.5:
    // they cycle at 2.2e-10 m/s for good).
    double zeno_close_time = 1e-8;
    // siconos-ed, with zeno_limit: an impact also ends the accumulation when
    // the law's next hop, (alpha u)^2 / (2 |g_n|), is lower than Lsodar's
    // error tolerance on the coordinate, rtol |q| + atol: the gap does not
    // change by it (it stays exactly 0), and Siconos's hops
    // stop shrinking there (Monte-Carlo scenarios of the stress suite: g up to
    // 8.8 m/s^2, alpha up to 0.94, hops cycling at 1e-8 to 3e-8 m/s, more than
    // 10000 roots within one step). Siconos has no such rule.
    bool zeno_close_below_resolution = true;
};

// What the adapter saw, for the tests.
struct Stats {
    std::int64_t steps = 0;
    std::int64_t new_contacts = 0;   // contacts that started (per-contact mode)
    std::int64_t beta_applied = 0;   // of them, counted by the law
    std::int64_t zeno_closures = 0;  // siconos-ed: impacts that closed a contact (zeno_limit applied)
    std::int64_t events = 0;         // siconos-ed: events processed
    std::int64_t roots = 0;          // siconos-ed: roots Lsodar found
};

class World : public EngineWorld {
public:
    virtual const Stats& stats() const = 0;
};

// The world the adapter builds for `s` (event_driven: siconos-ed), appending the settings used.
std::unique_ptr<World> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                   bool event_driven, std::vector<Setting>& settings);

// The simulators with any tuning (names "siconos" and "siconos-ed" as registered).
std::unique_ptr<const Simulator> make_time_stepping_simulator(const Tuning& tuning);
std::unique_ptr<const Simulator> make_event_driven_simulator(const Tuning& tuning);

}  // namespace bouncecheck::siconos

namespace bouncecheck {

// The registered "siconos" and "siconos-ed" simulators (registry/registry.cpp), with the adapter's tuning.
std::unique_ptr<const Simulator> make_siconos_simulator();
std::unique_ptr<const Simulator> make_siconos_event_driven_simulator();

}  // namespace bouncecheck
