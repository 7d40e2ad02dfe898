// The reference must be the document's model to the last bit: against the
// golden files (the document's own MATLAB functions run under GNU Octave), and
// against hand-worked steps of other rooms, balls, gravities, damping and steps.
#include "reference/plain_reference_model.h"
#include "reference/reference_model.h"
#include "scenarios/loader.h"
#include "tests/support/csv.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace bouncecheck {
namespace {

using test::read_csv;

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// Every state of the reference run of `s`, initial state first.
std::vector<State> run_all(const Scenario& s) {
    std::vector<State> out;
    auto visit = [&](auto model) {
        out.push_back(model.state());
        while (model.running()) {
            model.step();
            out.push_back(model.state());
        }
    };
    if (s.dim == 2) visit(ReferenceModel<2>(s));
    else visit(ReferenceModel<3>(s));
    return out;
}

void expect_matches_golden(const std::string& scenario_file, const std::string& golden_file) {
    const Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + scenario_file);
    const auto golden = read_csv(std::string(BOUNCECHECK_TEST_DATA) + "/" + golden_file);
    const auto states = run_all(s);
    ASSERT_EQ(states.size(), golden.rows.size());
    const int d = s.dim;
    int mismatches = 0;
    for (size_t n = 0; n < states.size(); ++n) {
        const auto& row = golden.rows[n];
        ASSERT_EQ(row.size(), static_cast<size_t>(1 + 2 * d));
        std::vector<double> ours{states[n].t};
        for (int i = 0; i < d; ++i) ours.push_back(states[n].p[i]);
        for (int i = 0; i < d; ++i) ours.push_back(states[n].v[i]);
        for (size_t c = 0; c < row.size(); ++c) {
            if (bits(ours[c]) != bits(row[c]) && ++mismatches <= 5) {
                ADD_FAILURE() << golden_file << " row " << n << " column " << golden.header[c]
                              << ": ours " << ours[c] << " golden " << row[c];
            }
        }
    }
    EXPECT_EQ(mismatches, 0);
}

TEST(ReferenceModel, Seed2dMatchesGoldenBitForBit) { expect_matches_golden("seed-2d.toml", "seed-2d.csv"); }
TEST(ReferenceModel, Seed3dMatchesGoldenBitForBit) { expect_matches_golden("seed-3d.toml", "seed-3d.csv"); }

TEST(ReferenceModel, StepCountFollowsTheDocumentsClock) {
    // 50 / 0.03 = 1666.67: the accumulated t passes 50 after 1667 steps.
    EXPECT_EQ(document_step_count(0.03, 50.0), 1667);
    EXPECT_EQ(document_step_count(0.03, 42.0), 1400);
    // 0.1 accumulated ten times is 0.9999999999999999 < 1: an eleventh step runs.
    EXPECT_EQ(document_step_count(0.1, 1.0), 11);
}

Scenario make_3d() {
    Scenario s;
    s.name = "hand";
    s.dim = 3;
    s.room = {2.0, 1.5, 1.0};
    s.radius = 0.1;
    s.position = {1.0, 0.75, 0.5};
    s.velocity = {0.0, 0.0, 0.0};
    s.gravity = {0.0, 0.0, -1.0};
    s.alpha = 0.5;
    s.beta = 0.75;
    s.dt = 0.25;
    s.duration = 10;
    return s;
}

// Hand-worked: free flight is Euler with position before velocity.
TEST(ReferenceModel, FreeFlightStepIsPositionThenVelocity) {
    Scenario s = make_3d();
    s.velocity = {0.5, -0.25, 1.0};
    ReferenceModel<3> m(s);
    const ContactMask c = m.step();
    EXPECT_FALSE(c.any());
    const State st = m.state();
    EXPECT_EQ(bits(st.p[0]), bits(1.0 + 0.5 * 0.25));
    EXPECT_EQ(bits(st.p[1]), bits(0.75 + -0.25 * 0.25));
    EXPECT_EQ(bits(st.p[2]), bits(0.5 + 1.0 * 0.25));  // old velocity moves the ball
    EXPECT_EQ(bits(st.v[2]), bits(1.0 + -1.0 * 0.25));
    EXPECT_EQ(bits(st.t), bits(0.25));
}

// Hand-worked floor contact in 3D: clamp to r, gravity, then v * diag(beta', beta', -alpha)
// where beta' = (alpha + beta) - alpha.
TEST(ReferenceModel, FloorContact3dClampsAndDamps) {
    Scenario s = make_3d();
    s.alpha = 0.8;
    s.beta = 0.99;  // (0.8 + 0.99) - 0.8 is computed, as in the document
    s.position = {1.0, 0.75, 0.15};
    s.velocity = {0.4, 0.2, -0.4};  // z moves to 0.05 < r
    ReferenceModel<3> m(s);
    const ContactMask c = m.step();
    EXPECT_EQ(c.lower, 0b100);
    EXPECT_EQ(c.upper, 0);
    const State st = m.state();
    EXPECT_EQ(bits(st.p[2]), bits(0.1));
    const double factor = (0.8 + 0.99) - 0.8;
    EXPECT_EQ(bits(st.v[0]), bits(0.4 * factor));
    EXPECT_EQ(bits(st.v[1]), bits(0.2 * factor));
    EXPECT_EQ(bits(st.v[2]), bits((-0.4 + -1.0 * 0.25) * -0.8));
}

// A corner in 3D: the lower multiply applies first, then the upper one, so a
// component touched by one wall gets -alpha there and beta' from the other.
TEST(ReferenceModel, CornerAppliesLowerThenUpperDiagonal) {
    Scenario s = make_3d();
    s.gravity = {0, 0, 0};
    s.position = {0.15, 1.35, 0.5};
    s.velocity = {-0.4, 0.4, 0.0};  // x to 0.05 (below r), y to 1.45 (above 1.5 - r)
    ReferenceModel<3> m(s);
    const ContactMask c = m.step();
    EXPECT_EQ(c.lower, 0b001);
    EXPECT_EQ(c.upper, 0b010);
    const State st = m.state();
    EXPECT_EQ(bits(st.p[0]), bits(0.1));
    EXPECT_EQ(bits(st.p[1]), bits(1.5 - 0.1));
    const double f = (0.5 + 0.75) - 0.5;
    EXPECT_EQ(bits(st.v[0]), bits((-0.4 * -0.5) * f));
    EXPECT_EQ(bits(st.v[1]), bits((0.4 * f) * -0.5));
    EXPECT_EQ(bits(st.v[2]), bits(0.0));
}

// 2D keeps the lower-left corner: tests q > 0 and q + 2r < size, clamps to 0
// and size - 2r, and reports the centre as corner + r.
TEST(ReferenceModel, CornerArithmeticIn2d) {
    Scenario s;
    s.dim = 2;
    s.room = {1.0, 2.0, 0};
    s.radius = 0.25;
    s.position = {0.75, 1.0, 0};  // corner (0.5, 0.75)
    s.velocity = {1.0, -4.0, 0};  // corner moves to (0.75, -0.25): x beyond 1 - 0.5, y below 0
    s.gravity = {0.0, -2.0, 0};
    s.alpha = 0.5;
    s.beta = 0.75;
    s.dt = 0.25;
    s.duration = 1;
    ReferenceModel<2> m(s);
    const ContactMask c = m.step();
    EXPECT_EQ(c.lower, 0b10);
    EXPECT_EQ(c.upper, 0b01);
    const State st = m.state();
    EXPECT_EQ(bits(st.p[0]), bits((1.0 - 2 * 0.25) + 0.25));
    EXPECT_EQ(bits(st.p[1]), bits(0.0 + 0.25));
    const double f = (0.5 + 0.75) - 0.5;
    EXPECT_EQ(bits(st.v[0]), bits((1.0 * f) * -0.5));
    EXPECT_EQ(bits(st.v[1]), bits(((-4.0 + -2.0 * 0.25) * -0.5) * f));
}

// The 2D ball of the seed starts with its top at the ceiling. In corner
// arithmetic it falls; in centre arithmetic it would stay glued there.
TEST(ReferenceModel, Seed2dBallLeavesTheCeiling) {
    const Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-2d.toml");
    ReferenceModel<2> m(s);
    const ContactMask c = m.step();
    EXPECT_FALSE(c.any());
    EXPECT_LT(m.state().v[1], 0.0);
}

// Subnormal products are computed in integer arithmetic: they must equal the
// hardware's correctly rounded products for every case, ties included.
TEST(ReferenceModel, SubnormalProductMatchesHardware) {
    const double factors[] = {0.99, (0.8 + 0.99) - 0.8, -0.8, 0.03, 0.5, 0.75, -1.0, 1.0, 1e-3, 0.0, -0.0,
                              1.5, 3.0, 1e10, 1e300, 0.49999999999999994};
    std::uint64_t state = 0x9E3779B97F4A7C15ull;
    auto next = [&] { state ^= state << 13; state ^= state >> 7; state ^= state << 17; return state; };
    for (double y : factors) {
        for (int n = 0; n < 20000; ++n) {
            std::uint64_t k = next() & 0x000FFFFFFFFFFFFFull;
            if (n < 100) k = static_cast<std::uint64_t>(n);  // the smallest, where ties are common
            const double x = std::bit_cast<double>(k | ((n & 1) ? 0x8000000000000000ull : 0));
            ASSERT_EQ(bits(detail::exact_product_small(x, y)), bits(x * y)) << "k=" << k << " y=" << y;
        }
    }
}

// A long run into the Zeno regime: tangential velocities reach the subnormal
// range, and the fast path must give the same bits as plain hardware arithmetic.
TEST(ReferenceModel, LongRunThroughSubnormalsMatchesPlainArithmetic) {
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-3d.toml");
    s.duration = 1e9;
    ReferenceModel<3> fast(s);
    PlainReferenceModel3d plain(s);
    bool saw_subnormal = false;
    // seed-3d's tangential velocities turn subnormal near step 1,053,000 and reach
    // a fixed point of the beta multiply about 7,000 steps later.
    for (int n = 0; n < 1100000; ++n) {
        fast.step();
        plain.step();
        const auto& p = plain.p;
        const auto& v = plain.v;
        const State st = fast.state();
        for (int i = 0; i < 3; ++i) {
            ASSERT_EQ(bits(st.p[i]), bits(p[i])) << "step " << n << " axis " << i;
            ASSERT_EQ(bits(st.v[i]), bits(v[i])) << "step " << n << " axis " << i;
            saw_subnormal = saw_subnormal || detail::is_subnormal(v[i]);
        }
    }
    EXPECT_TRUE(saw_subnormal) << "the run did not reach the subnormal range it is meant to test";
}

// The oracle itself is the document: the plain transcription reproduces the
// golden files too, in 2D (corner arithmetic) and 3D.
template <int D>
void expect_plain_matches_golden(const std::string& scenario_file, const std::string& golden_file) {
    const Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + scenario_file);
    const auto golden = read_csv(std::string(BOUNCECHECK_TEST_DATA) + "/" + golden_file);
    PlainReferenceModel<D> plain(s);
    DocumentClock clock(s.dt, s.duration);
    size_t n = 0;
    for (;; ++n) {
        ASSERT_LT(n, golden.rows.size());
        const State st = plain.state(clock.t());
        const auto& row = golden.rows[n];
        ASSERT_EQ(bits(st.t), bits(row[0])) << "row " << n;
        for (int i = 0; i < D; ++i) {
            ASSERT_EQ(bits(st.p[i]), bits(row[1 + i])) << "row " << n << " axis " << i;
            ASSERT_EQ(bits(st.v[i]), bits(row[1 + D + i])) << "row " << n << " axis " << i;
        }
        if (!clock.running()) break;
        plain.step();
        clock.advance();
    }
    EXPECT_EQ(n + 1, golden.rows.size());
}

// The free-flight loop's single comparison against the upper wall is the
// document's q + reach < size, for every double near the limit.
TEST(ReferenceModel, UpperLimitIsTheDocumentsTest) {
    const double sizes[] = {1.0, 0.3, 2.0, 1e-3, 7.25, 1e6};
    const double reaches[] = {0.05, 0.1, 0.025, 1e-17, 0.3, 2.5e-4};
    for (double size : sizes) {
        for (double reach : reaches) {
            const double h = detail::least_reaching(size, reach);
            double x = h;
            for (int k = 0; k < 2000; ++k) x = std::nextafter(x, -1e300);
            for (int k = 0; k < 4000; ++k, x = std::nextafter(x, 1e300))
                ASSERT_EQ(x + reach < size, x < h) << "size " << size << " reach " << reach << " x " << x;
        }
    }
}

TEST(PlainReferenceModel, MatchesGolden2d) { expect_plain_matches_golden<2>("seed-2d.toml", "seed-2d.csv"); }
TEST(PlainReferenceModel, MatchesGolden3d) { expect_plain_matches_golden<3>("seed-3d.toml", "seed-3d.csv"); }

void expect_same_bits(const State& got, const State& want, int dim, const std::string& where) {
    EXPECT_EQ(bits(got.t), bits(want.t)) << where << " t";
    for (int i = 0; i < dim; ++i) {
        EXPECT_EQ(bits(got.p[i]), bits(want.p[i])) << where << " p[" << i << "]: " << got.p[i] << " vs " << want.p[i];
        EXPECT_EQ(bits(got.v[i]), bits(want.v[i])) << where << " v[" << i << "]: " << got.v[i] << " vs " << want.v[i];
    }
}

// run_to_end() against the plain model over runs that end before, at, and
// long after the point where the resting state starts repeating. The plain
// model is stepped once to the longest run; each checkpoint N is a run of
// its own whose duration is the clock's t after N steps, so the document's
// loop takes exactly N steps. Returns the step at which the fast run of the
// longest checkpoint found its repeat.
template <int D>
std::int64_t expect_run_to_end_matches_plain(Scenario s, std::int64_t longest) {
    s.duration = 1e300;  // the plain loop below decides where to stop
    // Every step near the start (free flight and the first contacts), then
    // every 19,997th, then every step of a stretch far out in the resting
    // regime: 64 steps, every remainder of a period up to 64.
    std::vector<std::int64_t> checkpoints;
    for (std::int64_t n = 0; n <= 300; ++n) checkpoints.push_back(n);
    for (std::int64_t n = 301; n < longest - 64; n += 19997) checkpoints.push_back(n);
    for (std::int64_t n = longest - 64; n <= longest; ++n) checkpoints.push_back(n);

    PlainReferenceModel<D> plain(s);
    DocumentClock clock(s.dt, s.duration);
    std::int64_t found_at = 0;
    std::int64_t n = 0;
    for (const std::int64_t target : checkpoints) {
        for (; n < target; ++n) {
            plain.step();
            clock.advance();
        }
        Scenario run = s;
        run.duration = clock.t();
        ReferenceModel<D> fast(run);
        fast.run_to_end();
        const std::string where = "dim " + std::to_string(D) + ", run of " + std::to_string(n) + " steps";
        EXPECT_EQ(fast.steps(), n) << where;
        expect_same_bits(fast.state(), plain.state(clock.t()), D, where);
        if (::testing::Test::HasFailure()) return 0;
        found_at = fast.repeat_found_at();
    }
    return found_at;
}

TEST(ReferenceModel, RunToEndMatchesPlainThroughTheRepeatingRest3d) {
    const Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-3d.toml");
    // seed-3d's repeat is found near step 1,102,000 (period 30 steps).
    const std::int64_t longest = 1300000;
    const std::int64_t found_at = expect_run_to_end_matches_plain<3>(s, longest);
    EXPECT_GT(found_at, 0) << "the longest run never skipped: the periodic path went untested";
    EXPECT_LT(found_at, longest - 64) << "the stretch of every remainder lies past the repeat";
}

TEST(ReferenceModel, RunToEndMatchesPlainThroughTheRepeatingRest2d) {
    const Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-2d.toml");
    // seed-2d's repeat is found near step 1,249,000 (period 17 steps).
    const std::int64_t longest = 1400000;
    const std::int64_t found_at = expect_run_to_end_matches_plain<2>(s, longest);
    EXPECT_GT(found_at, 0) << "the longest run never skipped: the periodic path went untested";
    EXPECT_LT(found_at, longest - 64) << "the stretch of every remainder lies past the repeat";
}

// Random rooms, balls, gravities (any direction, so ceilings and side walls
// are floors too), damping and steps: run_to_end() and step() by step both
// equal the plain model, state by state for step() and at the end for
// run_to_end(). Short runs: the free-flight loop's exits at every wall.
template <int D>
void expect_random_scenarios_match_plain(std::uint64_t seed) {
    std::uint64_t state = seed;
    auto next = [&] { state ^= state << 13; state ^= state >> 7; state ^= state << 17; return state; };
    auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1p-53; };
    int repeated = 0;
    for (int trial = 0; trial < 200; ++trial) {
        Scenario s;
        s.dim = D;
        s.room = Vec3::Zero();
        s.position = Vec3::Zero();
        s.velocity = Vec3::Zero();
        s.gravity = Vec3::Zero();
        s.radius = uniform(0.01, 0.2);
        for (int i = 0; i < D; ++i) {
            s.room[i] = uniform(4 * s.radius, 3.0);
            s.position[i] = uniform(s.radius, s.room[i] - s.radius);
            s.velocity[i] = uniform(-2.0, 2.0);
            s.gravity[i] = (next() & 3) == 0 ? 0.0 : uniform(-10.0, 10.0);
        }
        s.alpha = uniform(0.1, 1.0);
        s.beta = uniform(0.5, 1.0);
        s.dt = uniform(1e-3, 0.05);
        s.duration = s.dt * uniform(10, 3000);

        ReferenceModel<D> stepped(s), fast(s);
        PlainReferenceModel<D> plain(s);
        DocumentClock clock(s.dt, s.duration);
        const std::string where = "dim " + std::to_string(D) + " trial " + std::to_string(trial);
        std::int64_t n = 0;
        for (; clock.running(); ++n) {
            stepped.step();
            plain.step();
            clock.advance();
            expect_same_bits(stepped.state(), plain.state(clock.t()), D, where + " step " + std::to_string(n));
            if (::testing::Test::HasFailure()) return;
        }
        fast.run_to_end();
        EXPECT_EQ(fast.steps(), n) << where;
        expect_same_bits(fast.state(), plain.state(clock.t()), D, where + " end");
        if (::testing::Test::HasFailure()) return;
        if (fast.repeat_found_at() > 0) ++repeated;
    }
    // Strong damping and gravity come to a repeating rest within the run.
    EXPECT_GT(repeated, 0) << "no trial reached a repeating state: the periodic path went untested";
}

TEST(ReferenceModel, RandomScenariosMatchPlain3d) { expect_random_scenarios_match_plain<3>(0x243F6A8885A308D3ull); }
TEST(ReferenceModel, RandomScenariosMatchPlain2d) { expect_random_scenarios_match_plain<2>(0x13198A2E03707344ull); }

}  // namespace
}  // namespace bouncecheck
