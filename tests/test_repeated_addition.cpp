// The closed form of a repeated floating-point addition (the document's
// clock, the comparison's running sums over a periodic tail) against the
// additions themselves, bit for bit.
#include "simulators/document_clock.h"
#include "simulators/repeated_addition.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace bouncecheck {
namespace {

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

double added(double s, const std::vector<double>& cycle, std::size_t phase, std::int64_t n) {
    for (std::int64_t k = 0; k < n; ++k) s = s + cycle[(phase + static_cast<std::size_t>(k)) % cycle.size()];
    return s;
}

std::int64_t additions_by_loop(double s, double step, double limit) {
    std::int64_t n = 0;
    for (; s < limit; ++n) s = s + step;
    return n;
}

// Values that make the roundings hard: ties (a value half-way between two
// units of the sum's binade), values the sum absorbs, zeros, subnormals,
// and values of every size in between.
double hard_value(std::mt19937_64& random, double sum_scale) {
    std::uniform_int_distribution<int> kind(0, 5);
    std::uniform_int_distribution<int> whole(0, 7);
    const double unit = std::ldexp(1.0, std::ilogb(sum_scale) - 52);
    switch (kind(random)) {
        case 0: return (whole(random) + 0.5) * unit;  // a tie
        case 1: return 0.25 * unit * whole(random);   // absorbed, or a tie at 2
        case 2: return 0.0;
        case 3: return std::numeric_limits<double>::denorm_min() * whole(random);
        default: return sum_scale * std::ldexp(std::uniform_real_distribution<double>(0.5, 1)(random), -whole(random) * 4);
    }
}

TEST(RepeatedAddition, SumAfterIsTheLoopsSumBitForBit) {
    std::mt19937_64 random(20261128);
    int cases = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const double scale = std::ldexp(1.0, std::uniform_int_distribution<int>(-1070, 60)(random));
        std::vector<double> cycle(std::uniform_int_distribution<std::size_t>(1, 9)(random));
        for (double& x : cycle) x = hard_value(random, scale);
        const double start = std::uniform_int_distribution<int>(0, 2)(random) == 0 ? 0.0 : scale * 3;
        const std::size_t phase = std::uniform_int_distribution<std::size_t>(0, 20)(random);
        const std::int64_t n = std::uniform_int_distribution<std::int64_t>(0, 20000)(random);
        SCOPED_TRACE(testing::Message() << "trial " << trial);
        ASSERT_EQ(bits(sum_after(start, cycle, phase, n)), bits(added(start, cycle, phase, n)));
        ++cases;
    }
    EXPECT_EQ(cases, 3000);
}

TEST(RepeatedAddition, LongSumsCrossManyBinades) {
    // The comparison's case: squared distances summed over a long tail.
    std::mt19937_64 random(7);
    for (int trial = 0; trial < 6; ++trial) {
        std::vector<double> cycle(std::uniform_int_distribution<std::size_t>(1, 40)(random));
        for (double& x : cycle) x = std::uniform_real_distribution<double>(0, 1e-6)(random);
        const std::int64_t n = 3'000'000;
        ASSERT_EQ(bits(sum_after(0.0, cycle, 3, n)), bits(added(0.0, cycle, 3, n))) << trial;
    }
}

TEST(RepeatedAddition, NegativeAndNonFiniteValuesAreAddedOneByOne) {
    const std::vector<double> negative{1e-3, -3e-4};
    EXPECT_EQ(bits(sum_after(1.0, negative, 0, 1001)), bits(added(1.0, negative, 0, 1001)));
    const std::vector<double> with_nan{1.0, std::nan("")};
    EXPECT_TRUE(std::isnan(sum_after(0.0, with_nan, 0, 5)));
    const std::vector<double> with_infinity{1.0, std::numeric_limits<double>::infinity()};
    EXPECT_EQ(sum_after(0.0, with_infinity, 0, 5), std::numeric_limits<double>::infinity());
}

TEST(RepeatedAddition, AdditionsToReachIsTheLoopsCount) {
    std::mt19937_64 random(42);
    for (int trial = 0; trial < 2000; ++trial) {
        const double step = std::ldexp(std::uniform_real_distribution<double>(1, 2)(random),
                                       std::uniform_int_distribution<int>(-30, 0)(random));
        // Steps that are ties in some binade the sum crosses: whole multiples of a half unit.
        const double tied = std::ldexp(std::round(std::ldexp(step, 20)) + 0.5, -20);
        const double s = std::uniform_int_distribution<int>(0, 1)(random) ? 0.0 : 7 * step;
        const double d = trial % 3 == 0 ? tied : step;
        const double limit = s + d * std::uniform_real_distribution<double>(0, 30000)(random);
        SCOPED_TRACE(testing::Message() << "trial " << trial << " step " << d << " limit " << limit);
        const std::int64_t expected = additions_by_loop(s, d, limit);
        ASSERT_EQ(additions_to_reach(s, d, limit, std::numeric_limits<std::int64_t>::max()), expected);
        EXPECT_EQ(additions_to_reach(s, d, limit, expected), expected);
        if (expected > 0) {
            EXPECT_FALSE(additions_to_reach(s, d, limit, expected - 1).has_value());
        }
    }
    // Steps that are ties in the binade the sum runs in, from a start with
    // an odd number of units: the first addition rounds the other way.
    for (int trial = 0; trial < 2000; ++trial) {
        const int e = std::uniform_int_distribution<int>(-30, 30)(random);
        const double unit = std::ldexp(1.0, e - 52), low = std::ldexp(1.0, e);
        const double step = (std::uniform_int_distribution<std::int64_t>(1, 1 << 20)(random) + 0.5) * unit;
        const double limit = 1.75 * low;
        double s = std::max(low, limit - step * std::uniform_int_distribution<int>(0, 30000)(random));
        s = (std::floor(s / unit) + (std::fmod(std::floor(s / unit), 2.0) == 0 ? 1 : 0)) * unit;
        SCOPED_TRACE(testing::Message() << "tie trial " << trial << " step " << step << " from " << s);
        ASSERT_EQ(additions_to_reach(s, step, limit, std::numeric_limits<std::int64_t>::max()),
                  additions_by_loop(s, step, limit));
    }
    // A sum that stops growing never gets there.
    EXPECT_FALSE(additions_to_reach(1.0, 1e-17, 2.0, std::numeric_limits<std::int64_t>::max()).has_value());
    EXPECT_EQ(additions_to_reach(3.0, 1.0, 2.0, 5), 0);
}

TEST(DocumentClockJumps, AsManyStepsAsTheLoopTakes) {
    for (const double dt : {0.03, 0.1, 1e-3, 1e-4, 0.0123456789, 1.0 / 3}) {
        for (const double duration : {1.0, 42.0, 50.0, 300.0, 1234.5678}) {
            SCOPED_TRACE(testing::Message() << "dt " << dt << " duration " << duration);
            DocumentClock looped(dt, duration);
            std::int64_t steps = 0;
            for (; looped.running(); looped.advance()) ++steps;
            EXPECT_EQ(document_step_count(dt, duration), steps);
            DocumentClock jumped(dt, duration);
            jumped.advance(steps);
            EXPECT_EQ(bits(jumped.t()), bits(looped.t()));
            EXPECT_FALSE(jumped.running());
        }
    }
    // The figures the document's loop gives (tests/data/README.md).
    EXPECT_EQ(document_step_count(0.03, 50.0), 1667);
    EXPECT_EQ(document_step_count(0.1, 1.0), 11);
}

// Clocks no loaded scenario has (the loader wants dt > 0), as code may make
// them: a negative dt counts |t| up, the mirror of the positive one; dt = 0
// never ends and counts as INT64_MAX (it looped forever before); a NaN dt
// ends after one step, as the document's loop does.
TEST(DocumentClockJumps, ClocksOutsideTheLoadersRange) {
    EXPECT_EQ(document_step_count(-0.1, 1.0), 11);
    EXPECT_EQ(document_step_count(-0.03, -50.0), 1667);
    EXPECT_EQ(document_step_count(0.0, 1.0), std::numeric_limits<std::int64_t>::max());
    EXPECT_EQ(document_step_count(std::nan(""), 1.0), 1);
    EXPECT_EQ(document_step_count(0.1, 0.0), 0);
}

}  // namespace
}  // namespace bouncecheck
