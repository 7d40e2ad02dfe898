// Calibration: the search finds the mu that minimises divergence, and the
// scenario file is edited without losing anything else.
#include "commands/calibrate/calibrate_pipeline.h"
#include "engines/engine.h"
#include "exact/exact_model.h"
#include "reference/reference_model.h"
#include "simulators/document_clock.h"
#include "scenarios/loader.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace bouncecheck {
namespace {

// A stand-in engine whose "friction" mu acts as a per-contact tangential
// factor 1 - mu: it equals the reference exactly at mu = 1 - beta.
class FrictionAsDampingEngine final : public EngineSimulator {
public:
    std::string_view name() const override { return "bullet"; }  // any engine name the loader knows
    std::string_view description() const override { return "test stand-in"; }
    EngineCapabilities capabilities() const override { return {}; }

protected:
    std::unique_ptr<EngineWorld> build(const Scenario& s, const EngineOptions& options,
                                       std::vector<Setting>& settings) const override {
        struct World final : EngineWorld {
            explicit World(const Scenario& s) : model(s) {}
            void step() override { model.step(); }
            void read(State& out) const override { out = model.state(); }
            ReferenceModel<3> model;
        };
        Scenario tuned = s;
        tuned.beta = 1.0 - options.friction;
        settings.push_back({"beta", std::to_string(tuned.beta), "1 - mu"});
        return std::make_unique<World>(tuned);
    }
};

// The same with the law's exact solution at beta = 1 - mu, sampled on the
// document clock: it equals exact at mu = 1 - beta.
class ExactWithFrictionAsDampingEngine final : public EngineSimulator {
public:
    std::string_view name() const override { return "ode"; }
    std::string_view description() const override { return "test stand-in"; }
    EngineCapabilities capabilities() const override { return {}; }

protected:
    std::unique_ptr<EngineWorld> build(const Scenario& s, const EngineOptions& options,
                                       std::vector<Setting>& settings) const override {
        struct World final : EngineWorld {
            explicit World(const Scenario& s) : model(s), clock(s.dt, s.duration) {}
            void step() override { clock.advance(); }
            void read(State& out) const override { out = model.state_at(clock.t()); }
            ExactModel model;
            DocumentClock clock;
        };
        Scenario tuned = s;
        tuned.beta = 1.0 - options.friction;
        settings.push_back({"beta", std::to_string(tuned.beta), "1 - mu"});
        return std::make_unique<World>(tuned);
    }
};

std::string read_text(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

TEST(Calibrate, FindsTheFrictionThatReproducesTheReference) {
    const Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-3d.toml");
    const FrictionAsDampingEngine engine;
    const CalibrationResult r = calibrate_friction(s, engine, 1.0);
    EXPECT_NEAR(r.mu, 0.01, 1e-3);
    EXPECT_LT(r.divergence, 0.01 * r.divergence_at_zero);
    EXPECT_GT(r.evaluated.size(), 15u);
}

TEST(Calibrate, AgainstExactFindsTheFrictionThatReproducesExact) {
    const Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-2d.toml");
    const ExactWithFrictionAsDampingEngine engine;
    const CalibrationResult r = calibrate_friction(s, engine, 1.0, CalibrationBaseline::exact);
    EXPECT_EQ(r.baseline, CalibrationBaseline::exact);
    EXPECT_NEAR(r.mu, 0.01, 1e-3);
    EXPECT_LT(r.divergence, 0.01 * r.divergence_at_zero);
    // Against the reference the same engine is not at zero distance: the
    // document's Euler is not the law's solution (its bounces are dt late).
    const CalibrationResult vs_reference = calibrate_friction(s, engine, 1.0, CalibrationBaseline::reference);
    EXPECT_GT(vs_reference.divergence, 10 * r.divergence);
}

CalibrationResult fitted(double mu, CalibrationBaseline baseline = CalibrationBaseline::reference) {
    CalibrationResult r;
    r.baseline = baseline;
    r.mu = mu;
    r.divergence = 0.01;
    return r;
}

TEST(Calibrate, WritesFrictionIntoTheEngineTable) {
    // seed-2d without its [engines] tables.
    std::string original = read_text(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-2d.toml");
    original = original.substr(0, original.find("\n#"));
    original = original.substr(0, original.find("[engines."));
    // No table yet: one is appended.
    const std::string added = with_calibrated_friction(original, "seed-2d.toml", "ode", fitted(0.125));
    EXPECT_EQ(added.substr(0, original.size()), original);
    EXPECT_NE(added.find("friction = 0.125  # bouncecheck calibrate: RMS distance 0.01 m from reference"),
              std::string::npos);
    EXPECT_NE(with_calibrated_friction(original, "x.toml", "ode", fitted(0.125, CalibrationBaseline::exact))
                  .find("RMS distance 0.01 m from exact"),
              std::string::npos);
    EXPECT_EQ(parse_scenario(added, "x.toml").engine_options("ode").friction, 0.125);
    // A table with a value: the value is replaced, other keys stay.
    const std::string with_table = original + "\n[engines.ode]\nfriction = 0.5\nrotation = \"locked\"\n";
    const Scenario replaced = parse_scenario(with_calibrated_friction(with_table, "x.toml", "ode", fitted(0.25)), "x.toml");
    EXPECT_EQ(replaced.engine_options("ode").friction, 0.25);
    EXPECT_FALSE(replaced.engine_options("ode").free_rotation);
    // A table without the key: it is inserted under the header.
    const std::string bare_table = original + "\n[engines.box2d]\nrotation = \"free\"\n";
    EXPECT_EQ(parse_scenario(with_calibrated_friction(bare_table, "x.toml", "box2d", fitted(0.0625)), "x.toml")
                  .engine_options("box2d")
                  .friction,
              0.0625);
}

}  // namespace
}  // namespace bouncecheck
