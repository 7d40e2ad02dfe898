// No work a scene does not need: once a run's states repeat (the reference's
// micro-bounce at rest, exact at rest), the rest of the run is handed over as
// a periodic tail instead of being stepped. Everything recorded must be what
// stepping on gives, bit for bit.
#include "adapters/simulator.h"
#include "compare/summary.h"
#include "reference/exact_model.h"
#include "reference/reference_model.h"
#include "reference/simulators.h"
#include "scenarios/loader.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <string>
#include <utility>

namespace bouncecheck {
namespace {

Scenario seed(const std::string& file) { return load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + file); }

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

void expect_same_state(const State& a, const State& b) {
    EXPECT_EQ(bits(a.t), bits(b.t));
    for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(bits(a.p[i]), bits(b.p[i])) << "p" << i << " at t = " << a.t;
        EXPECT_EQ(bits(a.v[i]), bits(b.v[i])) << "v" << i << " at t = " << a.t;
    }
}

// Every recorded field, bit for bit (timings and the fill marker aside).
void expect_same_summary(const SimulatorSummary& a, const SimulatorSummary& b) {
    EXPECT_EQ(a.status, b.status);
    EXPECT_EQ(a.reason, b.reason);
    EXPECT_EQ(a.steps, b.steps);
    EXPECT_EQ(a.contacts, b.contacts);
    EXPECT_EQ(a.floor_contacts, b.floor_contacts);
    EXPECT_EQ(a.apex_count, b.apex_count);
    ASSERT_EQ(a.apexes.size(), b.apexes.size());
    for (std::size_t i = 0; i < a.apexes.size(); ++i) {
        EXPECT_EQ(bits(a.apexes[i].t), bits(b.apexes[i].t)) << i;
        EXPECT_EQ(bits(a.apexes[i].height), bits(b.apexes[i].height)) << i;
    }
    ASSERT_EQ(a.contact_events.size(), b.contact_events.size());
    for (std::size_t i = 0; i < a.contact_events.size(); ++i) {
        const ContactEvent &x = a.contact_events[i], &y = b.contact_events[i];
        EXPECT_EQ(bits(x.t), bits(y.t)) << i;
        EXPECT_EQ(x.axis, y.axis);
        EXPECT_EQ(x.side, y.side);
        EXPECT_EQ(bits(x.normal_coefficient), bits(y.normal_coefficient)) << i;
        EXPECT_EQ(bits(x.tangential_retention), bits(y.tangential_retention)) << i;
    }
    EXPECT_EQ(bits(a.max_penetration), bits(b.max_penetration));
    EXPECT_EQ(bits(a.energy_max_rise), bits(b.energy_max_rise));
    ASSERT_EQ(a.rest_time.has_value(), b.rest_time.has_value());
    if (a.rest_time) {
        EXPECT_EQ(bits(*a.rest_time), bits(*b.rest_time));
    }
    expect_same_state(a.final_state, b.final_state);
}

// The reference stepped to the end, every state through the recorder: what
// the simulator did before periodic tails.
template <int D>
SimulatorSummary stepped_reference(const Scenario& s, StateSink* sink) {
    ReferenceModel<D> model(s);
    StreamRecorder recorder(s, sink);
    recorder.on_state(model.state(), ContactMask{});
    while (model.running() && !recorder.failed()) {
        const ContactMask contact = model.step();
        recorder.on_state(model.state(), contact);
    }
    SimulatorSummary out;
    recorder.finish(out);
    return out;
}

SimulatorSummary stepped(const Scenario& s, StateSink* sink) {
    return s.dim == 2 ? stepped_reference<2>(s, sink) : stepped_reference<3>(s, sink);
}

// Every state's bits folded into one FNV-1a digest, with the count: a
// sink for runs too long to keep.
class DigestSink final : public StateSink {
public:
    void write(const State& s) override {
        for (const double x : {s.t, s.p[0], s.p[1], s.p[2], s.v[0], s.v[1], s.v[2]}) {
            std::uint64_t b = bits(x);
            for (int i = 0; i < 8; ++i, b >>= 8) digest = (digest ^ (b & 0xFF)) * 0x100000001B3ull;
        }
        ++states;
    }
    std::uint64_t digest = 0xCBF29CE484222325ull;
    std::int64_t states = 0;
};

// Returns the filled run's summary.
SimulatorSummary expect_reference_tail_is_stepping(const Scenario& s) {
    SCOPED_TRACE(s.name + ", duration " + std::to_string(s.duration));
    DigestSink filled_states, stepped_states;
    const SimulatorSummary filled = make_reference_simulator()->run(s, &filled_states);
    const SimulatorSummary expected = stepped(s, &stepped_states);
    expect_same_summary(filled, expected);
    EXPECT_EQ(filled_states.states, stepped_states.states);
    EXPECT_EQ(filled_states.digest, stepped_states.digest);
    return filled;
}

// A ball dropped straight down: no tangential velocity left to decay, so the
// rest cycle starts within the first few thousand steps.
Scenario dropped(const std::string& file) {
    Scenario s = seed(file);
    s.velocity = Vec3::Zero();
    return s;
}

TEST(PeriodicTail, SeedRestIsHandedOverAndMatchesSteppingBitForBit) {
    // The seeds' tangential velocities decay by beta at every contact until
    // they reach zero or a fixed point: the states repeat from about 1.1e6
    // (3D, period 30) and 1.25e6 steps (2D, period 17).
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        Scenario s = seed(file);
        s.duration = 45000;  // 1.5e6 steps
        const SimulatorSummary r = expect_reference_tail_is_stepping(s);
        ASSERT_TRUE(r.filled_from.has_value()) << file;
        EXPECT_EQ(r.fill_period, s.dim == 3 ? 30 : 17);
        EXPECT_GT(*r.filled_from, 30000.0);
        EXPECT_LT(*r.filled_from, 40000.0);
    }
}

// When a stepped reference first finds its state repeating: (time, period).
template <int D>
std::pair<double, std::int64_t> first_repeat(const Scenario& s) {
    ReferenceModel<D> model(s);
    while (model.running() && model.repeat_period() == 0) model.step_finding_period();
    return {model.state().t, model.repeat_period()};
}

TEST(PeriodicTail, EveryTailLengthAndPhaseMatchesStepping) {
    // Runs ending at every tail length from none to over two cycles (every
    // phase of the cycle), and one where the kept contact list fills up
    // inside the tail (400 s: about 13,000 steps at rest).
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        Scenario s = dropped(file);
        s.duration = 1000;
        const auto [found_t, period] = s.dim == 2 ? first_repeat<2>(s) : first_repeat<3>(s);
        ASSERT_GT(period, 0) << file;
        int filled = 0;
        for (std::int64_t k = -2; k < 2 * period + 3; ++k) {
            s.duration = found_t + (static_cast<double>(period + k) + 0.5) * s.dt;
            filled += expect_reference_tail_is_stepping(s).filled_from.has_value();
        }
        // The run ends at the first sample at or past its duration: k + 1
        // tail states after the period that collects the cycle.
        EXPECT_EQ(filled, 2 * period + 3) << file;  // k >= 0: at least one tail state
        s.duration = 400;
        EXPECT_TRUE(expect_reference_tail_is_stepping(s).filled_from.has_value()) << file;
    }
}

TEST(PeriodicTail, OtherDampingsMatchStepping) {
    // alpha 0.5: the cycle's speeds cross the recorder's rest threshold, so
    // the rest start is re-derived in the last cycle; alpha 0 stops at once.
    for (const double alpha : {0.5, 0.0, 0.95}) {
        Scenario s = dropped("seed-3d.toml");
        s.alpha = alpha;
        s.duration = 2000;
        expect_reference_tail_is_stepping(s);
    }
}

TEST(PeriodicTail, DefaultSinkWritesEveryTailState) {
    PeriodicTail tail;
    tail.cycle = {State{0, {1, 2, 3}, {0, 0, 0}}, State{0, {4, 5, 6}, {0, 0, 0}}};
    tail.contacts = {ContactMask{}, ContactMask{1, 0}};
    tail.count = 5;
    tail.t_before = 0.1;
    tail.dt = 0.1;
    StateVector sink;
    sink.write_periodic(tail);
    ASSERT_EQ(sink.states.size(), 5u);
    double t = 0.1;
    for (std::size_t i = 0; i < 5; ++i) {
        t = t + 0.1;
        EXPECT_EQ(bits(sink.states[i].t), bits(t));
        EXPECT_EQ(sink.states[i].p.x(), i % 2 ? 4 : 1);
    }
}

}  // namespace
}  // namespace bouncecheck
