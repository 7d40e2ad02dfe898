// The Siconos side of the Siconos adapters, behind a plain C++17 header.
//
// Siconos 4.4's headers do not compile as C++20 (Boost 1.74 uBLAS calls
// std::allocator::construct, removed in C++20), so everything that includes
// them lives in siconos_model.cpp, compiled as C++17. This header names no
// Siconos type and no bouncecheck type beyond the standard library: the
// adapter (siconos_adapter.cpp, C++20) fills a ModelSpec from the scenario
// and drives a Model.
#pragma once

#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace bouncecheck::siconos_model {

enum class Scheme {
    moreau_jean,   // TimeStepping + MoreauJeanOSI + LCP / FrictionContact
    event_driven,  // EventDriven + LsodarOSI + impact and acceleration LCPs
};

// One wall of the room: the plane q[axis] = offset, facing inwards.
struct WallSpec {
    int axis = 0;
    int side = -1;  // -1 lower (offset 0), +1 upper
    double offset = 0;
};

// Every number the Siconos model is built from. Lengths in metres, times in
// seconds (no unit scale: no Siconos tolerance here is relative to a size the
// seed's 5 cm ball would fall below, see the adapter's settings).
struct ModelSpec {
    Scheme scheme = Scheme::moreau_jean;
    int dim = 3;                 // translational degrees of freedom (2 or 3)
    bool rotation = false;       // add the ball's rotational DOFs (1 in 2D, 3 in 3D)
    double mass = 1, radius = 0.05;
    std::array<double, 3> position{}, velocity{}, gravity{};
    std::vector<WallSpec> walls;
    double restitution = 0.8;    // NewtonImpactNSL e (alpha)
    double friction = 0;         // > 0: NewtonImpactFrictionNSL + FrictionContact (time-stepping only)
    double dt = 0.01;            // TimeDiscretisation step
    double final_time = 1;       // NonSmoothDynamicalSystem T (beyond the last sample)

    // MoreauJeanOSI
    double theta = 0.5;
    double gamma = std::numeric_limits<double>::quiet_NaN();  // NaN: Siconos's "not used" (prediction with 1/2)
    bool use_gamma_for_relation = false;
    double activation_threshold = 0;
    // The one-step nonsmooth problem (numerics SolverOptions)
    int lcp_solver = 0;          // numerics solver id (SICONOS_LCP_*); 0: Lemke
    double solver_tolerance = 1e-6;
    int solver_max_iterations = 10000;
    bool set_solver_options = true;  // false: numerics' defaults for the solver id

    // LsodarOSI / EventDriven
    double lsodar_rtol = 0, lsodar_atol = 0;  // <= 0: keep Siconos's
    double event_tolerance = 0;               // EventDriven::_TOL_ED; <= 0: keep Siconos's
};

// What Siconos says about one wall after a step or an event.
struct WallStatus {
    double gap = 0;        // y[0]: distance from the ball's surface to the wall
    double impulse = 0;    // time-stepping: lambda[1] normal (the step's contact impulse)
    // indexSet[1]: time-stepping, active this step; event-driven, touching as
    // of the last nonsmooth event (not updated at time-discretisation events:
    // the adapter reads the gap instead).
    bool in_impact_set = false;
    bool in_resting_set = false;  // event-driven: indexSet[2] (persistent contact)
};

struct Counters {
    long long events = 0;        // event-driven: events processed
    long long roots = 0;         // event-driven: roots Lsodar found (impacts, contact openings)
    long long solver_calls = 0;  // time-stepping: steps that solved a nonsmooth problem
};

// The values Siconos runs with, read back from the built objects.
struct Effective {
    double theta = 0, gamma = 0, activation_threshold = 0;
    bool use_gamma = false, use_gamma_for_relation = false;
    std::string solver;  // numerics solver name
    int solver_id = 0;
    double solver_tolerance = 0;
    int solver_max_iterations = 0;
    double lsodar_rtol = 0, lsodar_atol = 0;
    double event_tolerance = 0, tick = 0;
    unsigned long gap_limit_ticks = 0;
    int dofs = 0;
    std::string version;
};

// One Siconos simulation of the ball. Not thread-safe (see the adapter's
// "threads" setting); build and step on one thread at a time.
class Model {
public:
    explicit Model(const ModelSpec& spec);
    ~Model();
    Model(const Model&) = delete;
    Model& operator=(const Model&) = delete;

    // Time-stepping: computeOneStep (free state, the nonsmooth problem, state
    // update); the step is not closed until finish_step() (nextStep: memories
    // saved, index sets updated), so the adapter can adjust the state between.
    void compute_step();
    void finish_step();

    // Event-driven: advance to the next event (Lsodar integrates to the next
    // time-discretisation instant or the first root of the gap functions);
    // returns whether it stopped at a root. Then process it (impact LCP,
    // acceleration LCP, index sets).
    bool advance_to_event();
    void process_events();
    double current_time() const;   // the last processed event's time
    bool has_next_event() const;

    // The ball's state: translational position and velocity (dim components).
    std::array<double, 3> position() const;
    std::array<double, 3> velocity() const;
    // Writes into Siconos's own state vectors (the ones Lsodar's work vector
    // points at, and the ones the next step starts from).
    // refresh_outputs: recompute the walls' y and y_dot from the new state
    // (the index sets of the event being processed are built from them).
    void set_translation(const std::array<double, 3>& position, const std::array<double, 3>& velocity,
                         bool refresh_outputs = false);

    // One entry per wall in ModelSpec::walls order (at most six); read after
    // every step and event, so a fixed array rather than an allocation.
    using WallStatuses = std::array<WallStatus, 6>;
    WallStatuses walls() const;
    const Counters& counters() const { return counters_; }
    const Effective& effective() const { return effective_; }

private:
    void build(const ModelSpec& spec);
    struct Impl;
    std::unique_ptr<Impl> impl_;
    Counters counters_;
    Effective effective_;
};

}  // namespace bouncecheck::siconos_model
