// The part every engine adapter shares: contact detection from a state
// stream, the stepping loop, failure handling, capability checks.
#include "engines/engine.h"
#include "metrics/summary.h"
#include "reference/reference_simulator.h"
#include "scenarios/loader.h"
#include "simulators/document_clock.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace bouncecheck {
namespace {

Scenario seed3d() { return load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-3d.toml"); }

State at(double z, double vz) {
    State s;
    s.p = {0.5, 0.5, z};
    s.v = {0.0, 0.0, vz};
    return s;
}

TEST(StreamContactDetector, ContactLastingSeveralStepsCountsOnceWhenTheNormalVelocityTurns) {
    const Scenario s = seed3d();  // r = 0.05, dt = 0.03
    const StreamContactDetector d(s);
    // Falling onto the floor, squashed for two steps, then leaving.
    EXPECT_FALSE(d.detect(at(0.06, -0.10), at(0.052, -0.08)).any());
    EXPECT_FALSE(d.detect(at(0.052, -0.08), at(0.049, -0.02)).any());
    const ContactMask turn = d.detect(at(0.049, -0.02), at(0.050, 0.06));
    EXPECT_EQ(turn.lower, 0b100);
    EXPECT_FALSE(d.detect(at(0.050, 0.06), at(0.052, 0.06)).any());
}

TEST(StreamContactDetector, StoppingAtTheWallIsAContact) {
    const StreamContactDetector d(seed3d());
    EXPECT_EQ(d.detect(at(0.051, -0.05), at(0.05, 0.0)).lower, 0b100);
}

TEST(StreamContactDetector, JitterOfARestingBallIsNotAContact) {
    const StreamContactDetector d(seed3d());  // noise floor 0.01 * 0.0981 * 0.03 = 2.9e-5 m/s
    EXPECT_FALSE(d.detect(at(0.05, -1e-6), at(0.05, 1e-6)).any());
    EXPECT_TRUE(d.detect(at(0.05, -1e-4), at(0.05, 1e-6)).any());
}

TEST(StreamContactDetector, TurningInMidAirIsNotAContact) {
    const StreamContactDetector d(seed3d());
    // The apex of a flight: vz turns from + to - far from the ceiling.
    EXPECT_FALSE(d.detect(at(0.7, 0.001), at(0.7, -0.002)).any());
    // Near the ceiling it is a ceiling contact.
    EXPECT_EQ(d.detect(at(0.949, 0.05), at(0.95, -0.04)).upper, 0b100);
}

// The inline screen (a sign change faster than the noise floor) lets a few
// steps through to the full test; it must never change what is counted.
TEST(StreamContactDetector, ScreenedStepsAreDecidedByTheFullTest) {
    const StreamContactDetector d(seed3d());
    // Same sign, product underflowing to zero: screened in, not a contact.
    EXPECT_FALSE(d.detect(at(0.05, 1e-4), at(0.05, 4.9e-324)).any());
    // -0 after rising into the ceiling stops the ball there: a contact.
    EXPECT_EQ(d.detect(at(0.949, 0.05), at(0.95, -0.0)).upper, 0b100);
    // A NaN velocity is never a contact (the recorder fails the run instead).
    EXPECT_FALSE(d.detect(at(0.05, -0.05), at(0.05, std::nan(""))).any());
}

TEST(StreamContactDetector, TwoAxisCheckOfA2DSceneCountsWhatTheThreeAxisOneDoes) {
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-2d.toml");
    const StreamContactDetector d(s);
    auto at2 = [](double x, double y, double vx, double vy) { return State{0, {x, y, 0}, {vx, vy, 0}}; };
    const State cases[][2] = {
        {at2(0.06, 0.06, -0.1, -0.1), at2(0.05, 0.05, 0.08, 0.08)},  // the corner: two contacts
        {at2(0.5, 0.94, 0.01, 0.1), at2(0.5, 0.95, 0.01, -0.08)},    // the ceiling
        {at2(0.5, 0.5, 0.1, 0.001), at2(0.51, 0.5, 0.1, -0.002)},    // an apex in mid-air
    };
    for (const auto& c : cases) {
        const ContactMask two = d.detect<2>(c[0], c[1]), three = d.detect<3>(c[0], c[1]);
        EXPECT_EQ(two.lower, three.lower);
        EXPECT_EQ(two.upper, three.upper);
    }
    EXPECT_EQ(d.detect<2>(cases[0][0], cases[0][1]).lower, 0b11);
}

// The per-contact hooks' contact condition (the law's, as the reference and
// exact apply it).
TEST(MovesIntoWall, MovingInOrPressedByGravityAtRest) {
    EXPECT_TRUE(moves_into_wall(-0.1, 0.0, -1));     // falling onto the floor
    EXPECT_TRUE(moves_into_wall(0.1, -0.0981, +1));  // rising into the ceiling against gravity
    EXPECT_TRUE(moves_into_wall(0.0, -0.0981, -1));  // resting on the floor, pressed down
    EXPECT_FALSE(moves_into_wall(0.0, -0.0981, +1));  // at rest against the ceiling: gravity pulls away
    EXPECT_FALSE(moves_into_wall(0.1, -0.0981, -1));  // leaving the floor
    EXPECT_FALSE(moves_into_wall(0.0, 0.0, -1));      // touching, no motion, no gravity
}

// The recorder's per-state soundness test is fused with its energy: a
// non-finite velocity on an axis without gravity must still fail the run,
// and a finite velocity whose square overflows must not.
TEST(StreamRecorder, NonFiniteVelocityFailsAndAHugeFiniteOneDoesNot) {
    const Scenario s = seed3d();
    for (const double bad : {std::nan(""), std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity()}) {
        StreamRecorder recorder(s, nullptr);
        recorder.on_state(State{0, s.position, s.velocity}, {});
        recorder.on_state(State{s.dt, s.position, {bad, 0, 0}}, {});
        SimulatorSummary out;
        recorder.finish(out);
        EXPECT_EQ(out.status, RunStatus::failed) << bad;
        EXPECT_NE(out.reason.find("non-finite"), std::string::npos) << out.reason;
    }
    StreamRecorder recorder(s, nullptr);
    recorder.on_state(State{0, s.position, s.velocity}, {});
    recorder.on_state(State{s.dt, s.position, {1e200, 0, 0}}, {});
    SimulatorSummary out;
    recorder.finish(out);
    EXPECT_EQ(out.status, RunStatus::ok) << out.reason;
}

// A corner: two walls touched in one step. Each wall's normal component is
// reversed by alpha, so neither counts as the other's tangential one; only
// the third axis measures beta.
TEST(StreamRecorder, CornerContactMeasuresTangentialOnTheFreeAxisOnly) {
    Scenario s = seed3d();
    s.gravity = Vec3::Zero();  // the incoming velocity is the previous sample's
    StreamRecorder recorder(s, nullptr);
    recorder.on_state(State{0, {0.06, 0.5, 0.06}, {-0.1, 0.2, -0.3}}, {});
    ContactMask corner;
    corner.lower = 0b101;  // x and z lower walls
    recorder.on_state(State{s.dt, {0.05, 0.506, 0.05}, {0.08, 0.198, 0.24}}, corner);
    SimulatorSummary out;
    recorder.finish(out);
    ASSERT_EQ(out.contact_events.size(), 2u);
    for (const ContactEvent& e : out.contact_events) EXPECT_DOUBLE_EQ(e.tangential_retention, 0.99) << e.axis;
    EXPECT_DOUBLE_EQ(out.contact_events[0].normal_coefficient, 0.8);
    EXPECT_DOUBLE_EQ(out.contact_events[1].normal_coefficient, 0.8);
}

TEST(StreamRecorder, ACentreBeyondAWallFailsEvenByOneUlp) {
    const Scenario s = seed3d();
    StreamRecorder recorder(s, nullptr);
    recorder.on_state(State{0, s.position, s.velocity}, {});
    Vec3 p = s.position;
    p[1] = std::nextafter(s.room[1], 2.0);
    recorder.on_state(State{s.dt, p, s.velocity}, {});
    SimulatorSummary out;
    recorder.finish(out);
    EXPECT_EQ(out.status, RunStatus::failed);
    EXPECT_NE(out.reason.find("left the room"), std::string::npos) << out.reason;
}

// The recorder takes states in blocks (StreamRecorder::on_state): the
// same record, and the same states passed on, as recording each at once.
TEST(StreamRecorder, BlocksRecordWhatStateByStateRecords) {
    Scenario s = seed3d();
    s.duration = 40;  // 1,335 states: five blocks and a part
    struct Kept final : RunSink {
        bool on_state(const State& st, ContactMask c) override {
            stream.push_back({st, c});
            return true;
        }
        void on_periodic_tail(const PeriodicTail&) override { ADD_FAILURE() << "no tail in 40 s"; }
        std::vector<std::pair<State, ContactMask>> stream;
    } kept;
    make_reference_simulator()->run(s, kept);
    ASSERT_EQ(kept.stream.size(), 1335u);
    auto record = [&](bool one_at_a_time, StateVector& passed_on) {
        StreamRecorder recorder(s, &passed_on);
        for (const auto& [st, c] : kept.stream) {
            recorder.on_state(st, c);
            if (one_at_a_time) recorder.record_pending();
        }
        SimulatorSummary out;
        recorder.finish(out);
        return out;
    };
    StateVector blocked, single;
    const SimulatorSummary a = record(false, blocked), b = record(true, single);
    ASSERT_EQ(blocked.states.size(), kept.stream.size());
    ASSERT_EQ(single.states.size(), kept.stream.size());
    for (std::size_t i = 0; i < kept.stream.size(); ++i) {
        EXPECT_EQ(blocked.states[i].t, single.states[i].t) << i;
        EXPECT_EQ(blocked.states[i].p, single.states[i].p) << i;
    }
    EXPECT_EQ(a.steps, b.steps);
    EXPECT_GT(a.contacts, 20);
    EXPECT_EQ(a.contacts, b.contacts);
    EXPECT_GT(a.apex_count, 5);
    EXPECT_EQ(a.apex_count, b.apex_count);
    ASSERT_EQ(a.apexes.size(), b.apexes.size());
    for (std::size_t i = 0; i < a.apexes.size(); ++i) EXPECT_EQ(a.apexes[i].height, b.apexes[i].height) << i;
    ASSERT_EQ(a.contact_events.size(), b.contact_events.size());
    for (std::size_t i = 0; i < a.contact_events.size(); ++i)
        EXPECT_EQ(a.contact_events[i].normal_coefficient, b.contact_events[i].normal_coefficient) << i;
    EXPECT_EQ(a.max_penetration, b.max_penetration);
    EXPECT_EQ(a.energy_max_rise, b.energy_max_rise);
    EXPECT_EQ(a.rest_time, b.rest_time);
    EXPECT_EQ(a.final_state.p, b.final_state.p);
    EXPECT_EQ(a.final_state.t, b.final_state.t);
}

// A simulator that throws part-way through a block: the states it made
// before still reach the sink (Siconos's event-driven solver gives up so).
TEST(StreamRecorder, StatesBeforeAThrowAreRecorded) {
    struct Thrower final : Simulator {
        std::string_view name() const override { return "thrower"; }
        std::string_view description() const override { return "throws after 300 states"; }
        RunOutcome run(const Scenario& s, RunSink& sink) const override {
            for (int i = 0; i < 300; ++i) sink.on_state(State{i * s.dt, s.position, s.velocity}, {});
            throw std::runtime_error("gave up");
        }
    };
    StateVector reached;
    EXPECT_THROW(record_run(Thrower{}, seed3d(), &reached), std::runtime_error);
    EXPECT_EQ(reached.states.size(), 300u);
}

// A stand-in engine world: free flight with a hook to go wrong.
class FakeEngine final : public EngineSimulator {
public:
    explicit FakeEngine(int fail_at_step = -1, EngineCapabilities caps = {}) : fail_at_(fail_at_step), caps_(caps) {}
    std::string_view name() const override { return "ode"; }
    std::string_view description() const override { return "test stand-in"; }
    EngineCapabilities capabilities() const override { return caps_; }
    mutable int steps = 0;
    mutable double built_dt = 0;

protected:
    std::unique_ptr<EngineWorld> build(const Scenario& s, const EngineOptions&,
                                       std::vector<Setting>& settings) const override {
        settings.push_back({"gravity", "scenario's", "test"});
        built_dt = s.dt;
        struct World final : EngineWorld {
            World(const Scenario& s, const FakeEngine& e) : state{0, s.position, s.velocity}, dt(s.dt), engine(e) {}
            void step() override {
                if (++engine.steps == engine.fail_at_) state.p[0] = std::numeric_limits<double>::quiet_NaN();
            }
            void read(State& out) const override { out = state; }
            State state;
            double dt;
            const FakeEngine& engine;
        };
        return std::make_unique<World>(s, *this);
    }

private:
    int fail_at_;
    EngineCapabilities caps_;
};

TEST(EngineSimulator, SharedLoopStepsOnTheDocumentClock) {
    const Scenario s = seed3d();
    const FakeEngine engine;
    StateVector states;
    const SimulatorSummary r = record_run(engine, s, &states);
    EXPECT_EQ(r.status, RunStatus::ok);
    EXPECT_EQ(r.steps, document_step_count(s.dt, s.duration));
    EXPECT_EQ(engine.steps, r.steps);
    ASSERT_EQ(states.states.size(), static_cast<size_t>(r.steps + 1));
    DocumentClock clock(s.dt, s.duration);
    for (const State& st : states.states) {
        EXPECT_EQ(st.t, clock.t());
        clock.advance();
    }
    ASSERT_EQ(r.settings.size(), 2u);
    EXPECT_EQ(r.settings[0].key, "gravity");
    EXPECT_EQ(r.settings[1].key, "substeps");
    EXPECT_EQ(r.settings[1].value, "1 engine step of 0.03 s per scenario step");
}

TEST(EngineSimulator, SubstepsStepAWorldBuiltForTheShorterStep) {
    Scenario s = seed3d();
    s.engines["ode"].substeps = 3;  // the fake engine is named "ode"
    const FakeEngine engine;
    const SimulatorSummary r = record_run(engine, s);
    EXPECT_EQ(r.status, RunStatus::ok);
    EXPECT_EQ(r.steps, document_step_count(s.dt, s.duration));  // states on the scenario's clock
    EXPECT_EQ(engine.steps, 3 * r.steps);
    EXPECT_EQ(engine.built_dt, s.dt / 3);
    ASSERT_EQ(r.settings.size(), 2u);
    EXPECT_EQ(r.settings[1].value, "3 engine steps of 0.01 s per scenario step");
}

TEST(EngineSimulator, NonFiniteStateFailsTheRunAndStopsStepping) {
    const FakeEngine engine(/*fail_at_step=*/10);
    const SimulatorSummary r = record_run(engine, seed3d());
    EXPECT_EQ(r.status, RunStatus::failed);
    EXPECT_NE(r.reason.find("non-finite"), std::string::npos) << r.reason;
    EXPECT_EQ(engine.steps, 10);
    // Past the first block of states as well: the run stops at the state.
    const FakeEngine later(/*fail_at_step=*/300);
    StateVector states;
    const SimulatorSummary r2 = record_run(later, seed3d(), &states);
    EXPECT_EQ(r2.status, RunStatus::failed);
    EXPECT_EQ(later.steps, 300);
    EXPECT_EQ(r2.steps, 300);
    EXPECT_EQ(states.states.size(), 301u);
}

TEST(EngineSimulator, CapabilitiesDecideWhatRunsBeforeAnySetUp) {
    EngineCapabilities planar_only;
    planar_only.runs_3d = false;
    const FakeEngine engine(-1, planar_only);
    const auto why = engine.cannot_run(seed3d());
    ASSERT_TRUE(why.has_value());
    EXPECT_NE(why->find("2D engine"), std::string::npos) << *why;
    EXPECT_EQ(engine.steps, 0);

    EngineCapabilities no_hook;
    no_hook.per_contact_hook = false;
    Scenario s = seed3d();
    s.engines["ode"].tangential_model = TangentialModel::per_contact;
    EXPECT_TRUE(FakeEngine(-1, no_hook).cannot_run(s).has_value());
}

}  // namespace
}  // namespace bouncecheck
