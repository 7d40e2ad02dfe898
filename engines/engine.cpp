#include "engines/engine.h"

#include "simulators/document_clock.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace bouncecheck {

double max_ball_speed(const Scenario& s) {
    double v2 = s.velocity.squaredNorm();
    for (int i = 0; i < s.dim; ++i) v2 += 2 * std::abs(s.gravity[i]) * s.room[i];
    return std::sqrt(v2);
}

Setting tangential_unset_setting() {
    return {"tangential_model_chosen", "friction with mu = 0: frictionless, beta = 1 (none given)",
            "the scenario gives neither tangential_model nor friction: the law's beta is not followed, and "
            "the damping verdict's tangential loss fails wherever contacts slide; set [engines.<name>] "
            "friction (bouncecheck calibrate) or tangential_model = \"per-contact\""};
}

std::vector<Wall> room_walls(const Scenario& s) {
    std::vector<Wall> walls;
    for (int axis = 0; axis < s.dim; ++axis) {
        walls.push_back(Wall{axis, -1, 0.0});
        walls.push_back(Wall{axis, +1, s.room[axis]});
    }
    return walls;
}

namespace {

// The shared loop, for a scene of D dimensions: the per-step checks look at
// those axes only.
template <int D>
void step_world_to_end(const Scenario& s, EngineWorld& world, int substeps, RunSink& sink,
                       const StreamContactDetector& detector) {
    // Two states read into in turn: the previous one is kept, not copied.
    State states[2] = {State{0.0, s.position, s.velocity}, State{}};
    State* previous = &states[0];
    State* current = &states[1];
    if (!sink.on_state(*previous, ContactMask{})) return;
    for (DocumentClock clock(s.dt, s.duration); clock.running();) {
        for (int i = 0; i < substeps; ++i) world.step();
        clock.advance();
        world.read(*current);
        current->t = clock.t();
        if (!sink.on_state(*current, detector.detect<D>(*previous, *current))) return;
        std::swap(previous, current);
    }
}

}  // namespace

std::optional<std::string> EngineSimulator::cannot_run(const Scenario& s) const {
    const EngineCapabilities caps = capabilities();
    if (s.dim == 3 && !caps.runs_3d) return fmt::format("{} is a 2D engine: it cannot run a 3D scenario", name());
    if (s.dim == 2 && !caps.runs_2d) return fmt::format("{} cannot run a 2D scenario", name());
    if (s.engine_options(std::string(name())).tangential_model == TangentialModel::per_contact &&
        !caps.per_contact_hook)
        return fmt::format("{} has no per-contact hook for tangential_model = \"per-contact\"", name());
    return std::nullopt;
}

EngineSimulator::SteppedWorld EngineSimulator::build_stepped_world(
    const Scenario& s, std::vector<Setting>& settings) const {
    const EngineOptions options = s.engine_options(std::string(name()));
    SteppedWorld out;
    out.substeps = std::max(1, options.substeps);
    Scenario engine_scenario = s;
    engine_scenario.dt = s.dt / out.substeps;
    out.engine_dt = engine_scenario.dt;
    out.world = build(engine_scenario, options, settings);
    return out;
}


RunOutcome EngineSimulator::run(const Scenario& s, RunSink& sink) const {
    RunOutcome out;
    const StreamContactDetector detector(s);
    // Substeps: the world is built for dt / substeps and stepped that many
    // times per scenario step; only the scenario step's end is recorded.
    out.run_seconds = timed_seconds([&] {
        const SteppedWorld built = build_stepped_world(s, out.settings);
        const int substeps = built.substeps;
        if (s.engine_options(std::string(name())).tangential_unset) out.settings.push_back(tangential_unset_setting());
        out.settings.push_back(
            {"substeps", fmt::format("{} engine step{} of {} s per scenario step", substeps,
                                     substeps == 1 ? "" : "s", built.engine_dt),
             substeps == 1 ? "one engine step per scenario step (the document's step)"
                           : "scenario [engines.<name>] substeps: shorter engine steps against fast balls and large dt"});
        if (s.dim == 2) step_world_to_end<2>(s, *built.world, substeps, sink, detector);
        else step_world_to_end<3>(s, *built.world, substeps, sink, detector);
    });
    return out;
}

namespace {

class DefinedEngineSimulator final : public EngineSimulator {
public:
    explicit DefinedEngineSimulator(EngineDefinition d)
        : name_(d.identity.name), description_(d.identity.description), d_(std::move(d)) {
        d_.identity.name = name_;
        d_.identity.description = description_;
    }
    std::string_view name() const override { return d_.identity.name; }
    std::string_view description() const override { return d_.identity.description; }
    double typical_ns_per_step() const override { return d_.identity.typical_ns_per_step; }
    EngineCapabilities capabilities() const override { return d_.capabilities; }

protected:
    std::unique_ptr<EngineWorld> build(const Scenario& s, const EngineOptions& options,
                                       std::vector<Setting>& settings) const override {
        return d_.build(s, options, settings);
    }

private:
    std::string name_, description_;  // what the identity views: it may have viewed a caller's strings
    EngineDefinition d_;
};

}  // namespace

std::unique_ptr<const Simulator> make_engine_simulator(EngineDefinition definition) {
    return std::make_unique<DefinedEngineSimulator>(std::move(definition));
}

}  // namespace bouncecheck
