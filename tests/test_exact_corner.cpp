// exact where alpha = 1 drives the ball into an edge or corner: the nine
// Monte-Carlo scenarios of the bundled stress suite on which exact used to give
// up, two more from a 10,000-scenario set (copied into tests/data/exact_corner/
// with their provenance, tests/data/README.md) and an edge the ball slides
// along afterwards. They are checked against an
// independent 100-digit event-driven solution (event_driven.py there), the
// reference's convergence through the accumulation, and the law's invariants.
#include "exact/exact_model.h"
#include "reference/reference_model.h"
#include "scenarios/loader.h"
#include "support/convergence.h"
#include "support/csv.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace bouncecheck {
namespace {

const std::string kDir = std::string(BOUNCECHECK_TEST_DATA) + "/exact_corner/";

// The nine, all 3D with alpha = 1 and gravity pressing into a side wall and the floor.
const char* const kMonteCarloCorners[] = {"monte-carlo-0149", "monte-carlo-0206", "monte-carlo-0396",
                                          "monte-carlo-0516", "monte-carlo-0681", "monte-carlo-0695",
                                          "monte-carlo-0746", "monte-carlo-0754", "monte-carlo-0794"};

// monte-carlo-0681 grazes the ceiling at t = 0.794 s with a normal speed of
// 3e-8 m/s: the contact's time moves with the square root of a wall's
// position, and two 100-digit solutions whose walls differ by 1e-17 m part by
// 4.7e-6 m. Its agreement is bounded by that conditioning, not by exact.
bool grazes(const std::string& name) { return name == "monte-carlo-0681"; }

struct Golden {
    test::Csv csv;
    double accumulation = 0;  // when the independent solution rests the ball on the floor
};

Golden read_golden(const std::string& name) {
    Golden g{test::read_csv(kDir + name + ".csv")};
    for (const std::string& line : g.csv.comments)
        if (const auto at = line.find("accumulation "); at != std::string::npos)
            g.accumulation = std::stod(line.substr(at + 13));
    return g;
}

// How close exact must come to the 100-digit solution: position (m) and
// velocity (m/s) at every sample, and the accumulation time (s). Round-off
// for most (measured at most 3.4e-14 m and 1.1e-11 m/s); the others are
// bounded by the problem's own conditioning, measured by moving a wall by
// 1e-17 m in the 100-digit solution:
// - monte-carlo-0681 grazes the ceiling (see grazes()): 4.7e-6 m apart;
// - monte-carlo-9552 accumulates in a three-wall corner: its accumulation
//   time moves by 2.2e-6 s (exact's is 4.7e-6 s from it; 1.6e-10 m/s at the
//   last sample before it);
// - edge-slide-3d slides on after its lock, carrying the lock's 1e-8 s offset
//   (measured 2.4e-9 m, 4.8e-10 m/s);
// - the others' accumulation times move by up to 1.8e-8 s (exact: 4e-11 to
//   7e-8 s from them).
struct Agreement {
    double position = 1e-12, velocity = 1e-10, time = 1e-6;
};
Agreement agreement(const std::string& name) {
    if (grazes(name)) return {1e-5, 5e-5, 1e-4};
    if (name == "monte-carlo-9552") return {1e-12, 1e-9, 1e-5};
    if (name == "edge-slide-3d") return {1e-8, 2e-9, 1e-6};
    return {};
}

double energy(const Scenario& s, const State& st) { return 0.5 * st.v.squaredNorm() - s.gravity.dot(st.p); }

// At every sample of the document clock, exact agrees with the independent
// solution, and rests the ball where and when that solution does (agreement()).
TEST(ExactCorner, MatchesAnIndependent100DigitSolutionAtEverySample) {
    std::vector<std::string> names(std::begin(kMonteCarloCorners), std::end(kMonteCarloCorners));
    names.push_back("edge-slide-3d");
    names.push_back("monte-carlo-9552");
    for (const std::string& name : names) {
        const Scenario s = load_scenario(kDir + name + ".toml");
        const ExactModel exact(s);
        ASSERT_FALSE(exact.event_cap_hit()) << name;
        EXPECT_LT(exact.contacts().size(), 10'000u) << name;
        const Golden golden = read_golden(name);
        ASSERT_GT(golden.accumulation, 0) << name;
        ASSERT_TRUE(exact.rest_time().has_value()) << name;
        const Agreement tol = agreement(name);
        EXPECT_NEAR(*exact.rest_time(), golden.accumulation, tol.time) << name;

        std::size_t row = 0;
        double worst_p = 0, worst_v = 0;
        exact.sample_document_clock([&](const State& st) {
            ASSERT_LT(row, golden.csv.rows.size()) << name;
            const std::vector<double>& g = golden.csv.rows[row++];
            ASSERT_EQ(st.t, g[0]) << name << " row " << row;
            for (int i = 0; i < s.dim; ++i) {
                worst_p = std::max(worst_p, std::abs(st.p[i] - g[1 + i]));
                worst_v = std::max(worst_v, std::abs(st.v[i] - g[1 + s.dim + i]));
            }
        });
        EXPECT_EQ(row, golden.csv.rows.size()) << name;
        EXPECT_LT(worst_p, tol.position) << name;
        EXPECT_LT(worst_v, tol.velocity) << name;
    }
}

// The law never adds energy (alpha, beta <= 1), inside and after the
// accumulation, and the nine end at rest in the edge gravity presses them into.
TEST(ExactCorner, EnergyNeverGrowsAndTheBallEndsAtRestInTheEdge) {
    for (const char* name : kMonteCarloCorners) {
        const Scenario s = load_scenario(kDir + name + ".toml");
        const ExactModel exact(s);
        double previous = energy(s, exact.state_at(0));
        State last;
        exact.sample_document_clock([&](const State& st) {
            const double e = energy(s, st);
            EXPECT_LE(e, previous + 1e-12 * (1 + std::abs(previous))) << name << " t " << st.t;
            previous = e;
            for (int i = 0; i < s.dim; ++i) {
                EXPECT_GE(st.p[i], s.radius) << name;
                EXPECT_LE(st.p[i], s.room[i] - s.radius) << name;
            }
            last = st;
        });
        EXPECT_EQ(last.v, Vec3::Zero()) << name;
        for (int i = 0; i < s.dim; ++i) {
            if (s.gravity[i] == 0) continue;
            EXPECT_EQ(last.p[i], s.gravity[i] < 0 ? s.radius : s.room[i] - s.radius) << name << " axis " << i;
        }
    }
}

// Three pressed walls, the ball far from one: the x-z edge accumulates, both
// walls are locked together, and the ball slides along the edge under gravity's
// y component, then bounces elastically off the y wall (alpha = 1).
TEST(ExactCorner, AfterTheEdgeAccumulatesTheBallSlidesAlongIt) {
    const Scenario s = load_scenario(kDir + "edge-slide-3d.toml");
    const ExactModel exact(s);
    ASSERT_TRUE(exact.rest_time().has_value());
    const double rest = *exact.rest_time();
    const State sliding = exact.state_at(rest + 1.0);
    EXPECT_EQ(sliding.p.x(), s.radius);
    EXPECT_EQ(sliding.p.z(), s.radius);
    EXPECT_EQ(sliding.v.x(), 0.0);
    EXPECT_EQ(sliding.v.z(), 0.0);
    // From rest along y (every contact of the accumulation scaled v_y by beta).
    EXPECT_NEAR(sliding.v.y(), s.gravity.y() * 1.0, 1e-12);
    const WallContact& end_wall = exact.contacts().back();
    EXPECT_EQ(end_wall.axis, 1);
    EXPECT_GT(end_wall.t, rest);
    EXPECT_NEAR(std::abs(end_wall.v_after.y()), std::abs(end_wall.v_before.y()), 1e-15);
}

// monte-carlo-6573 (2D, alpha = 1, beta = 0): every contact stops the other
// axis, so the next contact comes at that axis's turning point and loses no
// energy. The corner's scale shrinks to a time scale of 8.4e-10 s (hops of
// 2.5e-18 m at 6e-9 m/s) by contact ~200 and then by 0.1% per 20,000 contacts:
// no accumulation a solver could reach. exact locks it once it has not halved
// in 10,000 contacts; the energy bound keeps the true ball that close to the
// corner and that slow for ever.
TEST(ExactCorner, ACornerThatStopsShrinkingIsLockedWithinItsEnergyBound) {
    const Scenario s = load_scenario(kDir + "monte-carlo-6573.toml");
    const ExactModel exact(s);
    ASSERT_FALSE(exact.event_cap_hit());
    ASSERT_TRUE(exact.rest_time().has_value());
    EXPECT_GT(exact.contacts().size(), 10'000u);
    EXPECT_LT(exact.contacts().size(), 20'000u);
    // The last contact before the lock: its energy above the corner bounds
    // everything after it.
    const WallContact& last = exact.contacts().back();
    double bound_speed = 0;
    for (int i = 0; i < s.dim; ++i) {
        const double g = std::abs(s.gravity[i]);
        const double d = s.gravity[i] < 0 ? last.p[i] - s.radius : s.room[i] - s.radius - last.p[i];
        const double energy = 0.5 * last.v_after[i] * last.v_after[i] + g * d;
        EXPECT_LT(energy / g, 1e-15 * s.room[i]) << "axis " << i;
        bound_speed = std::max(bound_speed, std::sqrt(2 * energy));
    }
    EXPECT_LT(bound_speed, 1e-8);
    const State end = exact.state_at(s.duration);
    EXPECT_EQ(end.v, Vec3::Zero());
    EXPECT_EQ(end.p.x(), s.room.x() - s.radius);
    EXPECT_EQ(end.p.y(), s.radius);
}

// monte-carlo-41554 (2D, alpha = 1, beta = 0) settles into such a cycle at a
// time scale of 5e-6 s, far above the lock's 1e-15 x room size: it is
// resolved contact by contact, and a run of the cap's length is named as a
// stalled corner, with its scale, rather than as an unexplained cap.
TEST(ExactCorner, ALargerStalledCycleEndsAtTheCapAndIsNamed) {
    const Scenario s = load_scenario(kDir + "monte-carlo-41554.toml");
    const ExactModel exact(s, 50'000);
    ASSERT_TRUE(exact.event_cap_hit());
    ASSERT_TRUE(exact.stalled_corner().has_value());
    EXPECT_GT(*exact.stalled_corner(), 1e-6);
    EXPECT_LT(*exact.stalled_corner(), 1e-5);
    // A corner that accumulates is never named.
    EXPECT_FALSE(ExactModel(load_scenario(kDir + "monte-carlo-0149.toml"), 500).stalled_corner().has_value());
}

// At every sample, the reference stepped at dt / 16 ... dt / 2048 approaches
// exact at first order: over the whole run, and from 10% before the
// accumulation to the end. Coarser steps are left out: there the error has
// saturated at the room's size (monte-carlo-0396: 0.33, 0.33, 0.29 m at the
// first three), which flattens the fit. Two are left out with their reason:
// - monte-carlo-0681 grazes the ceiling at 3e-8 m/s: a touch scales the
//   tangential velocity by beta however slow it is, and a stepped ball that
//   misses the exact apex by 1e-16 m never touches: O(1) apart at every dt;
// - monte-carlo-0794 starts touching the upper y wall and the ceiling,
//   moving into both. The reference applies one damping diagonal for both
//   (the document's code: one beta for the third axis), exact each wall's
//   contact in turn (beta^2, the limit of two contacts an instant apart):
//   O(1) apart from t = 0 at every dt (docs/models.md).
TEST(ExactCorner, ReferenceApproachesExactAtFirstOrderThroughTheAccumulation) {
    for (const char* name : kMonteCarloCorners) {
        if (grazes(name) || std::string(name) == "monte-carlo-0794") continue;
        Scenario s = load_scenario(kDir + name + ".toml");
        const ExactModel exact(s);
        const double from = 0.9 * *exact.rest_time();
        std::vector<double> dts, whole, through;
        const double dt0 = s.dt;
        for (int halvings = 4; halvings <= 11; ++halvings) {
            s.dt = dt0 / static_cast<double>(1 << halvings);
            ReferenceModel<3> reference(s);
            double sum = 0, sum_through = 0;
            long n = 0, n_through = 0;
            while (reference.running()) {
                reference.step();
                const State st = reference.state();
                const double e2 = (st.p - exact.state_at(st.t).p).squaredNorm();
                sum += e2;
                ++n;
                if (st.t >= from) {
                    sum_through += e2;
                    ++n_through;
                }
            }
            dts.push_back(s.dt);
            whole.push_back(std::sqrt(sum / static_cast<double>(n)));
            through.push_back(std::sqrt(sum_through / static_cast<double>(n_through)));
        }
        const double order = test::fitted_order(dts, whole), order_through = test::fitted_order(dts, through);
        std::printf("%s: fitted order %.2f over the run, %.2f from 0.9 x accumulation (rms %.3g .. %.3g m)\n", name,
                    order, order_through, whole.front(), whole.back());
        EXPECT_GT(order, 0.65) << name;
        EXPECT_LT(order, 1.3) << name;
        EXPECT_GT(order_through, 0.8) << name;
        EXPECT_LT(order_through, 1.4) << name;
    }
}

}  // namespace
}  // namespace bouncecheck
