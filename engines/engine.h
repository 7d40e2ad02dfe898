// What every engine adapter shares: the stepping loop, recording, the room's
// walls, unit scaling, contact detection from the state stream and settings
// reporting. An engine adapter only builds its world and steps it.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/simulator.h"
#include "simulators/stream_contacts.h"

#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

// What an engine can run, declared up front (asked before any set-up).
struct EngineCapabilities {
    bool runs_3d = true;
    bool runs_2d = true;        // natively or by constraining a 3D body to the vertical plane
    bool planar_2d_in_3d = false;  // 2D runs as a 3D body locked to the x-z plane
    bool per_contact_hook = true;  // supports TangentialModel::per_contact
    std::string precision;         // "double", "float"
};

// What an engine is, known without loading it: the registry
// (registry/engine_module.h) answers these from the adapter's header and
// loads the adapter's module only when a run needs the engine itself.
struct EngineIdentity {
    std::string_view name;
    std::string_view description;
    double typical_ns_per_step;  // Simulator::typical_ns_per_step
};

// Lengths and times in the engine's world: x_engine = x * length, t_engine = t * time.
// The law is scale-free when lengths, speeds and gravity scale together, so an
// engine tuned for metre-sized objects can run the 5 cm ball at a scale it likes.
struct UnitScale {
    double length = 1.0;
    double time = 1.0;
    double to_engine_length(double x) const { return x * length; }
    double to_engine_velocity(double v) const { return v * length / time; }
    double to_engine_acceleration(double a) const { return a * length / (time * time); }
    double to_engine_time(double t) const { return t * time; }
    // Read back every step (Box2D; Bullet and ODE run at scale 1 and read
    // their state as it is).
    double from_engine_length(double x) const { return x / length; }
    double from_engine_velocity(double v) const { return v * time / length; }
};

// One wall of the room: the plane x[axis] = offset, facing inwards.
struct Wall {
    int axis;
    int side;       // -1 lower (offset 0), +1 upper (offset room[axis])
    double offset;  // scenario units
};
std::vector<Wall> room_walls(const Scenario& s);

// The fastest the ball can ever move: its start speed plus the whole room to
// fall along every axis (the law never adds energy). Adapters size thick
// walls, unit scales and contact stiffness from it.
double max_ball_speed(const Scenario& s);

// The setting every engine's run shows when its scenario gave neither
// tangential_model nor friction (EngineOptions::tangential_unset).
Setting tangential_unset_setting();

// The law's contact condition for the per-contact hooks, at a wall the ball
// has just started touching (side -1 lower, +1 upper; normal components
// along the wall's axis): the ball moves into the wall, or rests against it
// with no normal velocity while gravity presses it in. A ball starting
// against a wall that gravity pulls it away from (seed-2d's ceiling at t = 0)
// is not in contact, as for the reference and exact.
inline bool moves_into_wall(double normal_velocity, double normal_gravity, int side) {
    return normal_velocity * side > 0 || (normal_velocity == 0 && normal_gravity * side > 0);
}

// A built engine world, stepped one engine step of the scenario's dt at a time.
class EngineWorld {
public:
    virtual ~EngineWorld() = default;
    // Exactly one engine step of the dt the world was built for (no
    // interpolation); the shared loop calls it `substeps` times per scenario step.
    virtual void step() = 0;
    // Ball centre and velocity in scenario units; the loop sets t.
    virtual void read(State& out) const = 0;
};

// Base of every engine adapter. Subclasses say what they can run, which
// settings they use, and build the world; run() is shared.
class EngineSimulator : public Simulator {
public:
    std::optional<std::string> cannot_run(const Scenario& s) const override;
    RunOutcome run(const Scenario& s, RunSink& sink) const final;
    bool third_party() const final { return true; }

    virtual EngineCapabilities capabilities() const = 0;

    // The world run() steps for `s`: built for dt / substeps (the scenario's
    // [engines.<name>] substeps, at least 1), stepped `substeps` times per
    // scenario step. Public so that a benchmark can step the same world bare.
    struct SteppedWorld {
        std::unique_ptr<EngineWorld> world;
        int substeps = 1;
        double engine_dt = 0;
    };
    SteppedWorld build_stepped_world(const Scenario& s, std::vector<Setting>& settings) const;

protected:
    // Builds the world for `s`, appending every setting that changes the answer to `settings`.
    virtual std::unique_ptr<EngineWorld> build(const Scenario& s, const EngineOptions& options,
                                               std::vector<Setting>& settings) const = 0;
};

// An engine adapter described by data: what it is, what it can run, and how
// it builds its world. Every adapter is one of these; only `build` differs.
// make_engine_simulator copies the identity's name and description.
struct EngineDefinition {
    EngineIdentity identity;
    EngineCapabilities capabilities;
    std::function<std::unique_ptr<EngineWorld>(const Scenario&, const EngineOptions&,
                                               std::vector<Setting>&)>
        build;
};
std::unique_ptr<const Simulator> make_engine_simulator(EngineDefinition definition);

}  // namespace bouncecheck
