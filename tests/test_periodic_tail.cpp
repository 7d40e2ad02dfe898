// No work a scene does not need: once a run's states repeat (the reference's
// micro-bounce at rest, exact at rest), the rest of the run is handed over as
// a periodic tail instead of being stepped. Everything recorded must be what
// stepping on gives, bit for bit.
#include "comparison/comparison.h"
#include "exact/exact_model.h"
#include "exact/exact_simulator.h"
#include "metrics/summary.h"
#include "reference/reference_model.h"
#include "reference/reference_simulator.h"
#include "reports/plot_data.h"
#include "scenarios/loader.h"
#include "simulators/simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

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
    const SimulatorSummary filled = record_run(*make_reference_simulator(), s, &filled_states);
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

// exact at rest: one state repeated, handed over from the first sample
// where the ball is still; before, every sample was evaluated.
TEST(PeriodicTail, ExactAtRestIsHandedOverAndMatchesSamplingBitForBit) {
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        Scenario s = seed(file);
        s.duration = 3000;
        SCOPED_TRACE(file);
        DigestSink filled_states, sampled_states;
        const SimulatorSummary filled = record_run(*make_exact_simulator(), s, &filled_states);
        const ExactModel model(s);
        StreamRecorder recorder(s, &sampled_states);
        model.sample_document_clock([&](const State& st) { recorder.on_state(st, ContactMask{}); });
        SimulatorSummary sampled;
        recorder.finish(sampled);
        EXPECT_EQ(filled.steps, sampled.steps);
        EXPECT_EQ(bits(filled.max_penetration), bits(sampled.max_penetration));
        EXPECT_EQ(bits(filled.energy_max_rise), bits(sampled.energy_max_rise));
        expect_same_state(filled.final_state, sampled.final_state);
        EXPECT_EQ(filled_states.states, sampled_states.states);
        EXPECT_EQ(filled_states.digest, sampled_states.digest);
        // Still from just after the Zeno time, long before the end.
        ASSERT_TRUE(filled.filled_from.has_value());
        ASSERT_TRUE(model.rest_time().has_value());
        EXPECT_GE(*filled.filled_from, *model.rest_time());
        EXPECT_LT(*filled.filled_from, *model.rest_time() + 1.0);
        EXPECT_EQ(filled.fill_period, 1);
    }
}

TEST(PeriodicTail, ExactSlidingAlongTheFloorIsNotHandedOver) {
    // beta = 1: after the Zeno time the ball keeps its tangential velocity
    // and slides into the side walls, so it is never still.
    Scenario s = seed("seed-2d.toml");
    s.beta = 1.0;
    s.duration = 200;
    const SimulatorSummary r = record_run(*make_exact_simulator(), s);
    EXPECT_FALSE(r.filled_from.has_value());
}

// The comparison's own lockstep reference replays its rest cycle instead of
// stepping: the distances must be those to the stepped reference.
TEST(PeriodicTail, ComparisonReplaysTheReferenceAtRestBitForBit) {
    Scenario s = dropped("seed-3d.toml");
    s.duration = 400;
    ASSERT_GT(first_repeat<3>(s).second, 0);  // the reference repeats within the run
    const ExactModel exact(s);
    TrajectoryComparer comparer(s, exact, std::nullopt, std::nullopt);
    ReferenceModel<3> reference(s);
    double sum_sq = 0, max = 0;
    std::int64_t n = 0;
    exact.sample_document_clock([&](const State& st) {
        comparer.write(st);
        if (n > 0) reference.step();
        // The RMS sums the squared distances as they are (no root and square).
        const double squared = (st.p - reference.state().p).squaredNorm();
        sum_sq += squared;
        max = std::max(max, std::sqrt(squared));
        ++n;
    });
    const TrajectoryDivergence d = comparer.vs_reference();
    EXPECT_EQ(d.samples, n);
    EXPECT_EQ(bits(d.rms), bits(std::sqrt(sum_sq / static_cast<double>(n))));
    EXPECT_EQ(bits(d.max), bits(max));
}

void expect_same_divergence(const TrajectoryDivergence& a, const TrajectoryDivergence& b) {
    EXPECT_EQ(a.samples, b.samples);
    EXPECT_EQ(bits(a.rms), bits(b.rms));
    EXPECT_EQ(bits(a.max), bits(b.max));
    EXPECT_EQ(bits(a.rms_before_rest), bits(b.rms_before_rest));
    EXPECT_EQ(bits(a.max_before_rest), bits(b.max_before_rest));
    ASSERT_EQ(a.first_exceeds.has_value(), b.first_exceeds.has_value());
    if (a.first_exceeds) {
        EXPECT_EQ(bits(*a.first_exceeds), bits(*b.first_exceeds));
    }
}

void expect_same_series(const DistanceSeries& a, const DistanceSeries& b) {
    const std::vector<double> &at = a.t, &bt = b.t, &av = a.distance, &bv = b.distance;
    ASSERT_EQ(at.size(), bt.size());
    for (std::size_t i = 0; i < at.size(); ++i) {
        EXPECT_EQ(bits(at[i]), bits(bt[i])) << i;
        EXPECT_EQ(bits(av[i]), bits(bv[i])) << i;
    }
}

// The reference's own stream compared with both baselines, as `run` does:
// handed over as a tail, against written state by state.
TEST(PeriodicTail, ComparisonOfATailMatchesStateByStateBitForBit) {
    struct Case {
        Scenario s;
        std::int64_t stride;
    };
    std::vector<Case> cases;
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        Scenario dropped_ball = dropped(file);
        dropped_ball.duration = 400;
        cases.push_back({dropped_ball, 7});
        Scenario long_run = seed(file);
        long_run.duration = 45000;
        cases.push_back({long_run, 2503});
    }
    for (const Case& c : cases) {
        SCOPED_TRACE(c.s.name + ", duration " + std::to_string(c.s.duration));
        const ExactModel exact(c.s);
        // A rest cut inside the tail, so both sides of it are exercised.
        const std::optional<double> cut = c.s.duration * 0.9;
        TrajectoryComparer tail(c.s, exact, cut, exact.rest_time()), each(c.s, exact, cut, exact.rest_time());
        tail.record_series(c.stride);
        each.record_series(c.stride);
        const SimulatorSummary filled = record_run(*make_reference_simulator(), c.s, &tail);
        ASSERT_TRUE(filled.filled_from.has_value());
        stepped(c.s, &each);
        expect_same_divergence(tail.vs_reference(), each.vs_reference());
        expect_same_divergence(tail.vs_exact(), each.vs_exact());
        expect_same_series(*tail.reference_series(), *each.reference_series());
        expect_same_series(*tail.exact_series(), *each.exact_series());
    }
}

// The baselines shared once per scenario (share_baselines) give every
// comparison the figures it makes on its own, bit for bit: with a track that
// ends inside the run (the comparer steps the reference on from where it
// ends), one that covers it, one that ends inside a handed-over tail, and a
// stream whose times are not the clock's (exact is then evaluated).
TEST(PeriodicTail, SharedBaselinesGiveTheComparisonsOwnFiguresBitForBit) {
    struct Case {
        Scenario s;
        std::int64_t track_samples;
    };
    std::vector<Case> cases;
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        for (const std::int64_t cap : {std::int64_t{1}, std::int64_t{500}, std::int64_t{1'000'000}})
            cases.push_back({seed(file), cap});
        Scenario long_run = seed(file);
        long_run.duration = 45000;  // the reference hands over a tail at about 1.1e6 steps
        cases.push_back({long_run, 1'000});
        cases.push_back({long_run, 1'200'000});
    }
    for (const Case& c : cases) {
        SCOPED_TRACE(c.s.name + ", duration " + std::to_string(c.s.duration) + ", track " +
                     std::to_string(c.track_samples));
        const ExactModel exact(c.s);
        const auto track = TrajectoryComparer::share_baselines(c.s, exact, c.track_samples);
        const std::optional<double> cut = c.s.duration * 0.5;
        for (const Simulator* sim : {make_reference_simulator().release(), make_exact_simulator().release()}) {
            const std::unique_ptr<const Simulator> owned(sim);
            SCOPED_TRACE(std::string(sim->name()));
            TrajectoryComparer shared(c.s, exact, cut, exact.rest_time(), track), own(c.s, exact, cut, exact.rest_time());
            shared.record_series(97);
            own.record_series(97);
            record_run(*sim, c.s, &shared);
            record_run(*sim, c.s, &own);
            expect_same_divergence(shared.vs_reference(), own.vs_reference());
            expect_same_divergence(shared.vs_exact(), own.vs_exact());
            expect_same_series(*shared.reference_series(), *own.reference_series());
            expect_same_series(*shared.exact_series(), *own.exact_series());
        }
    }
    // Times off the clock (an imported trajectory's): exact at those times.
    const Scenario s = seed("seed-3d.toml");
    const ExactModel exact(s);
    StateVector states;
    record_run(*make_reference_simulator(), s, &states);
    TrajectoryComparer shared(s, exact, std::nullopt, std::nullopt, TrajectoryComparer::share_baselines(s, exact)),
        own(s, exact, std::nullopt, std::nullopt);
    for (State st : states.states) {
        st.t += 0.25 * s.dt;
        shared.write(st);
        own.write(st);
    }
    expect_same_divergence(shared.vs_exact(), own.vs_exact());
    expect_same_divergence(shared.vs_reference(), own.vs_reference());
    EXPECT_GT(own.vs_exact().max, 0.0);
}

// The reference's own row is compared with no second reference beside it
// (TrajectoryComparer::of_the_reference: a zero distance at every sample).
// It gives what comparing its stream with a lockstep reference gives, bit
// for bit, once its rest cut is set: from the run, with and without a shared
// track, through a handed-over tail.
TEST(PeriodicTail, TheReferencesOwnComparisonIsTheLockstepOneBitForBit) {
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        Scenario long_run = seed(file);
        long_run.duration = 45000;
        for (const Scenario& s : {seed(file), long_run}) {
            const ExactModel exact(s);
            for (const std::int64_t track_samples : {std::int64_t{0}, std::int64_t{500}}) {
                SCOPED_TRACE(s.name + ", duration " + std::to_string(s.duration) + ", track " +
                             std::to_string(track_samples));
                const auto track = track_samples > 0 ? TrajectoryComparer::share_baselines(s, exact, track_samples)
                                                     : nullptr;
                const SimulatorSummary reference = record_run(*make_reference_simulator(), s);
                if (s.duration > 1000) {
                    ASSERT_TRUE(reference.rest_time.has_value());  // the cut is exercised
                }
                TrajectoryComparer itself = TrajectoryComparer::of_the_reference(s, exact, exact.rest_time(), track);
                TrajectoryComparer lockstep(s, exact, reference.rest_time, exact.rest_time(), track);
                itself.record_series(97);
                lockstep.record_series(97);
                const SimulatorSummary filled = record_run(*make_reference_simulator(), s, &itself);
                record_run(*make_reference_simulator(), s, &lockstep);
                EXPECT_EQ(filled.filled_from.has_value(), s.duration > 1000);
                TrajectoryDivergence own = itself.vs_reference();
                EXPECT_FALSE(own.rest_cut.has_value());
                own.rest_cut = filled.rest_time;
                expect_same_divergence(own, lockstep.vs_reference());
                EXPECT_EQ(lockstep.vs_reference().max, 0.0);
                expect_same_divergence(itself.vs_exact(), lockstep.vs_exact());
                EXPECT_GT(lockstep.vs_exact().max, 0.0);
                expect_same_series(*itself.reference_series(), *lockstep.reference_series());
                expect_same_series(*itself.exact_series(), *lockstep.exact_series());
            }
        }
    }
}

void expect_same_trace(const PlotTrace& a, const PlotTrace& b) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(bits(a.t[i]), bits(b.t[i])) << i;
        for (int k = 0; k < 3; ++k) EXPECT_EQ(bits(a.p[i][k]), bits(b.p[i][k])) << i;
    }
}

// The plotted path of a tail (the decimator jumps from kept state to kept
// state once no turning point can be kept) is the path of its every state.
TEST(PeriodicTail, PlotTraceOfATailMatchesStateByStateBitForBit) {
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        Scenario dropped_ball = dropped(file);
        dropped_ball.duration = 400;
        Scenario long_run = seed(file);
        long_run.duration = 45000;
        for (const Scenario& s : {dropped_ball, long_run}) {
            for (const std::size_t budget : {7u, 600u}) {
                SCOPED_TRACE(s.name + ", duration " + std::to_string(s.duration) + ", budget " +
                             std::to_string(budget));
                // The reference micro-bounces at rest: its cycle reverses,
                // until the turning points' budget is spent.
                TraceDecimator filled(expected_states(s), s.dim, budget), each(expected_states(s), s.dim, budget);
                ASSERT_TRUE(record_run(*make_reference_simulator(), s, &filled).filled_from.has_value());
                stepped(s, &each);
                expect_same_trace(filled.finish(), each.finish());
                // Exact at rest: a cycle of one still state, never reversing.
                TraceDecimator exact_filled(expected_states(s), s.dim, budget),
                    exact_each(expected_states(s), s.dim, budget);
                ASSERT_TRUE(record_run(*make_exact_simulator(), s, &exact_filled).filled_from.has_value());
                ExactModel(s).sample_document_clock([&](const State& st) { exact_each.write(st); });
                expect_same_trace(exact_filled.finish(), exact_each.finish());
            }
        }
    }
}

// The metrics recorder hands its sink blocks of states (StateSink::
// write_block). The comparison and the plotted path take a block of any
// size, across the end of the shared track, as they take its states one by
// one, bit for bit.
TEST(SinkBlocks, ComparisonAndPlotTakeBlocksOfAnySizeAsSingleStatesBitForBit) {
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        const Scenario s = seed(file);
        SCOPED_TRACE(s.name);
        const ExactModel exact(s);
        // exact's stream: a distance to the reference at almost every sample.
        std::vector<State> stream;
        exact.sample_document_clock([&](const State& st) { stream.push_back(st); });
        ASSERT_GT(stream.size(), 1000u);
        const auto track = TrajectoryComparer::share_baselines(s, exact, 500);
        const std::optional<double> cut = s.duration * 0.5;
        TrajectoryComparer single(s, exact, cut, exact.rest_time(), track),
            blocked(s, exact, cut, exact.rest_time(), track);
        single.record_series(7);
        blocked.record_series(7);
        TraceDecimator single_path(expected_states(s), s.dim, 50), blocked_path(expected_states(s), s.dim, 50);
        for (const State& st : stream) {
            single.write(st);
            single_path.write(st);
        }
        const std::size_t sizes[] = {1, 3, 256, 100, 511, 2};
        for (std::size_t at = 0, k = 0; at < stream.size(); ++k) {
            const std::size_t n = std::min(sizes[k % std::size(sizes)], stream.size() - at);
            const std::span<const State> block(stream.data() + at, n);
            blocked.write_block(block);
            blocked_path.write_block(block);
            at += n;
        }
        EXPECT_GT(single.vs_reference().max, 0.0);
        EXPECT_TRUE(single.vs_reference().first_exceeds.has_value());
        expect_same_divergence(single.vs_reference(), blocked.vs_reference());
        expect_same_divergence(single.vs_exact(), blocked.vs_exact());
        expect_same_series(*single.reference_series(), *blocked.reference_series());
        expect_same_series(*single.exact_series(), *blocked.exact_series());
        expect_same_trace(single_path.finish(), blocked_path.finish());
    }
}

// The sweep's unrecorded run jumps over a tail: the same steps and final
// state as the recorded run that takes it state by state.
TEST(PeriodicTail, UnrecordedRunJumpsToTheRecordedFinalState) {
    for (const char* file : {"seed-3d.toml", "seed-2d.toml"}) {
        Scenario s = seed(file);
        s.duration = 45000;
        SCOPED_TRACE(file);
        const auto exact = make_exact_simulator();
        const SimulatorSummary recorded = record_run(*exact, s);
        ASSERT_TRUE(recorded.filled_from.has_value());
        const UnrecordedRun unrecorded = exact->run_unrecorded(s);
        EXPECT_EQ(unrecorded.steps, recorded.steps);
        expect_same_state(unrecorded.final_state, recorded.final_state);
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
