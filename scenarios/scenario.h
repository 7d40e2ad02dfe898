// A validated room-and-ball scenario: the immutable model every simulator runs.
#pragma once

#include <Eigen/Core>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace bouncecheck {

using Vec3 = Eigen::Vector3d;

// How an engine reproduces the tangential damping beta ([engines.<name>]).
enum class TangentialModel {
    friction,     // Coulomb friction with coefficient `friction` (mu), tuned by `bouncecheck calibrate`
    per_contact,  // mu = 0; the engine's contact callback scales tangential velocity by beta once per contact
};

// Per-engine settings of a scenario: the table [engines.<name>].
struct EngineOptions {
    TangentialModel tangential_model = TangentialModel::friction;
    double friction = 0.0;      // mu, friction model only
    bool free_rotation = true;  // false locks the ball's rotation
    // Continuous collision detection against the walls; unset keeps the
    // adapter's own choice (docs/engines.md). ODE has none.
    std::optional<bool> ccd;
    // Engine steps per scenario step, each of dt / substeps (engines/engine.cpp).
    int substeps = 1;
    // Neither tangential_model nor friction was given in a scenario file:
    // friction mode with no mu, which is frictionless (beta = 1). The run
    // says so in its settings, and the damping verdict's tangential loss
    // fails it wherever the contacts have tangential motion.
    bool tangential_unset = false;
};

// CI limits on a simulator's divergence from the reference and its error
// against exact ([thresholds], [thresholds.<simulator>], --threshold). An
// unset limit is not checked.
struct ThresholdSet {
    std::optional<int> bounce_count;          // how many bounces (apexes) to compare
    // Against the reference (the document's model):
    std::optional<double> bounce_height_rel;  // largest relative apex-height divergence over them
    std::optional<double> trajectory_rms;     // RMS centre distance over the run (m)
    std::optional<double> trajectory_max;     // largest centre distance over the run (m)
    // The damping law, measured at the contacts (verdicts/verdicts.h):
    std::optional<double> restitution_abs;      // largest |measured normal coefficient - alpha|
    std::optional<double> tangential_abs;       // largest |measured tangential retention - beta|
    std::optional<double> tangential_loss_rel;  // |mean loss - (1 - beta)| / max(1 - beta, 0.01)
    // Against exact (the law's truth), for "is my engine right?":
    std::optional<double> error_bounce_height_rel;  // largest relative apex-height error over the bounces
    std::optional<double> error_contact_time;       // largest floor-contact time error over them (s)
    std::optional<double> error_trajectory_rms;     // RMS centre error before exact's rest (m)
    std::optional<double> error_trajectory_max;     // largest centre error before exact's rest (m)

    // This set with every limit `over` sets replaced by `over`'s.
    ThresholdSet overridden_by(const ThresholdSet& over) const;
};

// Every limit of a ThresholdSet but bounce_count (an integer), by its key:
// the one list the loader, --threshold and the reports read.
struct ThresholdLimit {
    const char* key;
    std::optional<double> ThresholdSet::*member;
};
inline constexpr ThresholdLimit kThresholdLimits[] = {
    {"bounce_height_rel", &ThresholdSet::bounce_height_rel},
    {"trajectory_rms", &ThresholdSet::trajectory_rms},
    {"trajectory_max", &ThresholdSet::trajectory_max},
    {"restitution_abs", &ThresholdSet::restitution_abs},
    {"tangential_abs", &ThresholdSet::tangential_abs},
    {"tangential_loss_rel", &ThresholdSet::tangential_loss_rel},
    {"error_bounce_height_rel", &ThresholdSet::error_bounce_height_rel},
    {"error_contact_time", &ThresholdSet::error_contact_time},
    {"error_trajectory_rms", &ThresholdSet::error_trajectory_rms},
    {"error_trajectory_max", &ThresholdSet::error_trajectory_max},
};

inline ThresholdSet ThresholdSet::overridden_by(const ThresholdSet& over) const {
    ThresholdSet out = *this;
    if (over.bounce_count) out.bounce_count = over.bounce_count;
    for (const ThresholdLimit& limit : kThresholdLimits)
        if (over.*limit.member) out.*limit.member = over.*limit.member;
    return out;
}

struct Thresholds {
    ThresholdSet all;                               // [thresholds]
    std::map<std::string, ThresholdSet> simulator;  // [thresholds.<simulator>], overriding `all`
    ThresholdSet for_simulator(const std::string& name) const {
        const auto it = simulator.find(name);
        return it == simulator.end() ? all : all.overridden_by(it->second);
    }
};

// Immutable once loaded (see scenarios/loader.h). Vectors hold `dim` used
// components; in 2D the third component is zero and ignored. The vertical axis
// is the last used one: index dim - 1 (z in 3D, y in 2D).
struct Scenario {
    std::string name;
    std::string description;
    std::filesystem::path source;  // file it was loaded from; empty if built in code

    int dim = 3;           // 2 or 3
    Vec3 room{1, 1, 1};    // room side lengths; the room spans [0, room[i]] on each axis
    double radius = 0.05;  // ball radius
    Vec3 position{0.5, 0.95, 0.5};  // ball centre at t = 0
    Vec3 velocity{0.3, 0.1, 0.2};   // at t = 0
    Vec3 gravity{0, 0, -0.0981};    // with its sign

    double alpha = 0.8;   // normal damping: normal component reversed and scaled at a contact
    double beta = 0.99;   // tangential damping: every other component scaled at a contact

    double dt = 0.03;        // step of the stepped simulators, and sample spacing of exact
    double duration = 42.0;  // simulated time

    // [engines.<name>] tables; an engine without one runs with
    // `unlisted_engines`: EngineOptions{}, marked tangential_unset by the loader.
    std::map<std::string, EngineOptions> engines;
    EngineOptions unlisted_engines;
    // External simulators this file declares ([external.<name>] command: the
    // program and its arguments, docs/external.md), and the [engines.<name>]
    // table of each external simulator, as JSON text: handed to the program
    // as written, never interpreted here.
    std::map<std::string, std::vector<std::string>> externals;
    std::map<std::string, std::string> passthrough_tables;
    Thresholds thresholds;

    int vertical_axis() const { return dim - 1; }
    EngineOptions engine_options(const std::string& engine) const {
        const auto it = engines.find(engine);
        return it == engines.end() ? unlisted_engines : it->second;
    }
};

}  // namespace bouncecheck
