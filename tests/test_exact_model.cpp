#include "exact/exact_model.h"
#include "tests/support/scenarios.h"
#include "scenarios/loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace bouncecheck {
namespace {

using test::make_scenario;

Scenario seed_3d() { return Scenario{}; }  // the Scenario defaults are seed-3d

Scenario seed_2d() {
    return make_scenario(2, {1, 1, 0}, 0.05, {0.5, 0.95, 0}, {0.3, 0, 0}, {0, -0.0981, 0}, 0.8, 0.99, 50);
}

// A ball dropped from rest, centre `drop` above its resting height.
Scenario drop(double drop_height, double g, double alpha, double beta = 0.99, Vec3 velocity = Vec3::Zero()) {
    return make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.5, 0.05 + drop_height}, velocity, {0, 0, -g}, alpha, beta, 20);
}

// A random room, ball and gravity (some with a tangential component), alpha
// in [alpha_low, 1), beta in [0, 1): scenario n of a sequence.
Scenario random_room(std::mt19937_64& rng, int n, double alpha_low, double dt = 0.03) {
    std::uniform_real_distribution<double> unit(0, 1);
    const int dim = n % 2 ? 2 : 3;
    Vec3 room(0.5 + unit(rng), 0.5 + unit(rng), dim == 3 ? 0.5 + unit(rng) : 0.0);
    Vec3 p = Vec3::Zero(), v = Vec3::Zero(), g = Vec3::Zero();
    for (int i = 0; i < dim; ++i) {
        p[i] = 0.1 + unit(rng) * (room[i] - 0.2);
        v[i] = 2 * unit(rng) - 1;
        g[i] = n % 3 ? 0.0 : 2 * unit(rng) - 1;  // some with tangential gravity
    }
    g[dim - 1] = -1 - 9 * unit(rng);
    return make_scenario(dim, room, 0.05, p, v, g, alpha_low + (1 - alpha_low) * unit(rng), unit(rng), 20, dt);
}

double energy(const Scenario& s, const State& st) { return 0.5 * st.v.squaredNorm() - s.gravity.dot(st.p); }

void expect_inside(const Scenario& s, const State& st) {
    for (int i = 0; i < s.dim; ++i) {
        ASSERT_GE(st.p[i], s.radius) << "axis " << i << " t " << st.t;
        ASSERT_LE(st.p[i], s.room[i] - s.radius) << "axis " << i << " t " << st.t;
    }
}

TEST(ExactModelDrop, HitsFloorAtFreeFallTime) {
    for (const double h : {0.45, 0.9, 1e-3}) {
        const double g = 9.81;
        const ExactModel model(drop(h, g, 0.8));
        ASSERT_FALSE(model.contacts().empty());
        const WallContact& c = model.contacts().front();
        EXPECT_EQ(c.axis, 2);
        EXPECT_EQ(c.side, -1);
        EXPECT_NEAR(c.t, std::sqrt(2 * h / g), 1e-12 * std::sqrt(2 * h / g));
        EXPECT_EQ(c.p[2], 0.05);
    }
}

TEST(ExactModelDrop, ApexHeightsScaleByAlphaSquared) {
    // beta = 1 and gravity only along z: side-wall contacts leave v_z alone, and
    // the fast sideways motion keeps the tail from being summed for many hops.
    const double alpha = 0.8;
    const Scenario s = make_scenario(2, {1, 1, 0}, 0.05, {0.5, 0.95, 0}, {3, 0, 0}, {0, -9.81, 0}, alpha, 1.0, 20);
    const ExactModel model(s);
    const auto& apexes = model.apexes();
    ASSERT_GE(apexes.size(), 6u);
    EXPECT_EQ(apexes.front().t, 0.0);  // at rest vertically in flight at the start
    EXPECT_EQ(apexes.front().height, 0.95);
    for (std::size_t k = 1; k < apexes.size(); ++k) {
        const double ratio = (apexes[k].height - s.radius) / (apexes[k - 1].height - s.radius);
        EXPECT_NEAR(ratio, alpha * alpha, 1e-9) << "apex " << k;
        EXPECT_GT(apexes[k].t, apexes[k - 1].t);
    }
}

TEST(ExactModelZeno, DropRestTimeMatchesClosedForm) {
    for (const double alpha : {0.1, 0.5, 0.8, 0.95}) {
        const double g = 9.81;
        const ExactModel model(drop(0.45, g, alpha));
        const double t0 = std::sqrt(2 * 0.45 / g);
        const double v0 = g * t0;
        ASSERT_TRUE(model.rest_time());
        EXPECT_NEAR(*model.rest_time(), t0 + 2 * alpha * v0 / (g * (1 - alpha)), 1e-9 * *model.rest_time());
        EXPECT_EQ(model.summed_tail_contacts(), -1);
        // The tail after the first impact is summed: its hops are listed
        // from the closed form, and nothing else is there.
        EXPECT_EQ(model.contacts().size() - model.listed_tail_contacts().size(), 1u);
        ASSERT_FALSE(model.listed_tail_contacts().empty());
        EXPECT_NEAR(model.listed_tail_contacts().front().t, t0 + 2 * alpha * v0 / g, 1e-12);
    }
}

TEST(ExactModelZeno, RestsOnFloorAfterAccumulation) {
    const Scenario s = drop(0.45, 9.81, 0.8);
    const ExactModel model(s);
    ASSERT_TRUE(model.rest_time());
    for (const double t : {*model.rest_time(), *model.rest_time() + 1e-9, s.duration}) {
        const State st = model.state_at(t);
        EXPECT_EQ(st.p[2], s.radius);
        EXPECT_EQ(st.v, Vec3::Zero());
        EXPECT_EQ(st.p[0], 0.5);
        EXPECT_EQ(st.p[1], 0.5);
    }
}

TEST(ExactModelZeno, TailStateFollowsTheHopSequence) {
    // The summed tail is evaluated in closed form: compare it with the hops
    // computed one by one.
    const double g = 9.81, alpha = 0.7, beta = 0.9;
    const Scenario s = drop(0.45, g, alpha, beta, {0.01, 0, 0});
    const ExactModel model(s);
    ASSERT_EQ(model.summed_tail_contacts(), -1);
    const WallContact& first = model.contacts().front();
    double t = first.t, u = first.v_after[2], x = first.p[0], vx = first.v_after[0];
    for (int k = 0; k < 30; ++k) {
        const double hop = 2 * u / g;
        for (const double f : {0.25, 0.5, 0.9}) {
            const State st = model.state_at(t + f * hop);
            const double tol = 1e-12 * std::max(1.0, 1 / (u * u));
            EXPECT_NEAR(st.p[2], s.radius + u * f * hop - 0.5 * g * f * hop * f * hop, 1e-12) << k;
            EXPECT_NEAR(st.v[2], u - g * f * hop, 1e-12 * (1 + g * hop)) << k;
            EXPECT_NEAR(st.p[0], x + vx * f * hop, 1e-12) << k;
            EXPECT_NEAR(st.v[0], vx, tol * std::abs(vx)) << k;
        }
        t += hop;
        x += vx * hop;
        u *= alpha;
        vx *= beta;
    }
}

TEST(ExactModelZeno, TangentialTravelMatchesClosedForm) {
    const double g = 9.81, alpha = 0.8, beta = 0.99;
    const Vec3 v{0.1, -0.05, 0};
    const Scenario s = make_scenario(3, {10, 10, 1}, 0.05, {5, 5, 0.5}, v, {0, 0, -g}, alpha, beta, 20);
    const ExactModel model(s);
    ASSERT_EQ(model.contacts().size() - model.listed_tail_contacts().size(), 1u);  // and the summed tail's
    const WallContact& c = model.contacts().front();
    const double u = c.v_after[2];
    const double tail_time = (2 * u / g) / (1 - alpha * beta);
    const State rest = model.state_at(*model.rest_time() + 1);
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(rest.p[i], c.p[i] + c.v_after[i] * tail_time, 1e-12);
    EXPECT_EQ(rest.v, Vec3::Zero());  // beta < 1: infinitely many contacts stop the sliding
    EXPECT_EQ(rest.p[2], s.radius);
}

TEST(ExactModelZeno, BetaOneSlidesAfterRestAndBouncesOffSideWalls) {
    const double g = 9.81, alpha = 0.8;
    const Scenario s = make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.5, 0.5}, {0.05, 0, 0}, {0, 0, -g}, alpha, 1.0, 60);
    const ExactModel model(s);
    ASSERT_TRUE(model.rest_time());
    const WallContact& last_floor = model.contacts().front();
    ASSERT_EQ(last_floor.axis, 2);
    const State rest = model.state_at(*model.rest_time());
    EXPECT_EQ(rest.v[0], last_floor.v_after[0]);  // beta = 1: the tail keeps the sliding speed
    EXPECT_EQ(rest.v[2], 0.0);
    // Sliding on the floor, it reaches the side wall with the floor axis locked.
    const std::size_t after_tail = 1 + model.listed_tail_contacts().size();  // past the summed tail's listed hops
    ASSERT_GE(model.contacts().size(), after_tail + 1);
    const WallContact& side = model.contacts()[after_tail];
    EXPECT_GT(side.t, *model.rest_time());
    EXPECT_EQ(side.axis, 0);
    EXPECT_EQ(side.side, +1);
    EXPECT_EQ(side.p[2], s.radius);
    EXPECT_EQ(side.v_after[2], 0.0);
    EXPECT_DOUBLE_EQ(side.v_after[0], -alpha * side.v_before[0]);
}

TEST(ExactModelZeno, SeedRestTimeMatchesLastResolvedBounce) {
    for (const Scenario& s : {seed_3d(), seed_2d()}) {
        const ExactModel model(s);
        ASSERT_TRUE(model.rest_time());
        const WallContact& c = model.contacts().back();
        const int z = s.vertical_axis();
        ASSERT_EQ(c.axis, z);
        const double g = -s.gravity[z];
        EXPECT_NEAR(*model.rest_time(), c.t + 2 * c.v_after[z] / (g * (1 - s.alpha)), 1e-12 * *model.rest_time());
        EXPECT_EQ(model.state_at(s.duration).v, Vec3::Zero());
    }
}

TEST(ExactModelSeed, Seed3dBouncesOffBackWallAtStart) {
    const ExactModel model(seed_3d());
    ASSERT_FALSE(model.contacts().empty());
    const WallContact& c = model.contacts().front();
    EXPECT_EQ(c.t, 0.0);
    EXPECT_EQ(c.axis, 1);
    EXPECT_EQ(c.side, +1);
    EXPECT_DOUBLE_EQ(c.v_after[0], 0.3 * 0.99);
    EXPECT_DOUBLE_EQ(c.v_after[1], -0.08);
    EXPECT_DOUBLE_EQ(c.v_after[2], 0.2 * 0.99);
    // The state at t = 0 is the one after the contact.
    EXPECT_EQ(model.state_at(0).v, c.v_after);
    EXPECT_GT(model.contacts()[1].t, 0.0);  // and it is not re-detected
}

TEST(ExactModelCorner, EqualTimesApplyBothWalls) {
    const double alpha = 0.8, beta = 0.9;
    const Scenario s = make_scenario(2, {1, 1, 0}, 0.05, {0.5, 0.5, 0}, {1, 1, 0}, Vec3::Zero(), alpha, beta, 1);
    const ExactModel model(s);
    ASSERT_EQ(model.contacts().size(), 2u);
    const WallContact &a = model.contacts()[0], &b = model.contacts()[1];
    EXPECT_EQ(a.t, b.t);
    EXPECT_EQ(a.axis, 0);
    EXPECT_EQ(b.axis, 1);
    EXPECT_EQ(a.side, +1);
    EXPECT_EQ(b.side, +1);
    EXPECT_EQ(b.v_before, a.v_after);  // applied one after the other, in axis order
    EXPECT_DOUBLE_EQ(b.v_after[0], -alpha * beta);
    EXPECT_DOUBLE_EQ(b.v_after[1], -alpha * beta);
    EXPECT_EQ(b.p, Vec3(0.95, 0.95, 0));
}

TEST(ExactModelCorner, GravityShotIntoFloorEdgeAppliesBothWalls) {
    // Reaches x = size - r exactly when it reaches the floor, with the times
    // computed by different root formulas (linear vs quadratic).
    const double g = 1, alpha = 0.8, beta = 0.9;
    const double fall = std::sqrt(2 * 0.45 / g);
    const Scenario s =
        make_scenario(2, {1, 1, 0}, 0.05, {0.5, 0.5, 0}, {0.45 / fall, 0, 0}, {0, -g, 0}, alpha, beta, 0.5 * fall + fall);
    const ExactModel model(s);
    ASSERT_GE(model.contacts().size(), 2u);
    const WallContact &a = model.contacts()[0], &b = model.contacts()[1];
    EXPECT_EQ(a.t, b.t);
    EXPECT_EQ(a.axis, 0);
    EXPECT_EQ(a.side, +1);
    EXPECT_EQ(b.axis, 1);
    EXPECT_EQ(b.side, -1);
    EXPECT_NEAR(b.v_after[0], -alpha * beta * 0.45 / fall, 1e-12);
    EXPECT_NEAR(b.v_after[1], alpha * beta * g * fall, 1e-12);
}

TEST(ExactModelCorner, ThreeWallsAtOnce) {
    const Scenario s = make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.5, 0.5}, {-1, 1, -1}, Vec3::Zero(), 0.8, 0.9, 1);
    const ExactModel model(s);
    ASSERT_EQ(model.contacts().size(), 3u);
    for (const WallContact& c : model.contacts()) EXPECT_EQ(c.t, model.contacts().front().t);
    EXPECT_DOUBLE_EQ(model.contacts().back().v_after[0], 0.8 * 0.81);
    EXPECT_DOUBLE_EQ(model.contacts().back().v_after[1], -0.8 * 0.81);
    EXPECT_DOUBLE_EQ(model.contacts().back().v_after[2], 0.8 * 0.81);
}

TEST(ExactModelBounds, StaysInsideRoomAtRandomTimes) {
    std::mt19937_64 rng(12345);
    const Scenario random_scenario = make_scenario(3, {0.7, 1.3, 0.4}, 0.03, {0.2, 0.9, 0.3}, {2.1, -1.7, 0.9},
                                                   {0.4, -0.3, -9.81}, 0.9, 0.95, 30);
    for (const Scenario& s : {seed_3d(), seed_2d(), random_scenario}) {
        const ExactModel model(s);
        std::uniform_real_distribution<double> time(0, s.duration);
        for (int n = 0; n < 100'000; ++n) expect_inside(s, model.state_at(time(rng)));
        for (const WallContact& c : model.contacts()) expect_inside(s, model.state_at(c.t));
    }
}

bool same_bits(const State& a, const State& b) {
    return std::memcmp(&a.t, &b.t, sizeof(double)) == 0 && std::memcmp(a.p.data(), b.p.data(), 3 * sizeof(double)) == 0 &&
           std::memcmp(a.v.data(), b.v.data(), 3 * sizeof(double)) == 0;
}

// The cursor a compared stream walks exact with gives state_at's bits at
// every sample: through a summed Zeno tail (where it keeps the current
// hop), corners, tangential gravity, fine steps that land many samples in
// one hop, and times that step back or repeat (it searches again). Its
// positions() of blocks of states give the same positions.
TEST(ExactModelCursor, GivesStateAtsBitsAtEveryTime) {
    std::vector<Scenario> scenarios{seed_3d(), seed_2d(), drop(0.45, 9.81, 0.8, 0.9, {0.01, 0, 0})};
    Scenario fine = seed_3d();
    fine.dt = 1e-4;
    scenarios.push_back(fine);
    std::mt19937_64 rng(99);
    for (int n = 0; n < 30; ++n) scenarios.push_back(random_room(rng, n, 0.5, 1e-3));
    int tails = 0;
    for (const Scenario& s : scenarios) {
        const ExactModel model(s);
        tails += model.summed_tail_contacts() != 0;
        ExactModel::Cursor cursor(model);
        std::int64_t samples = 0, differ = 0;
        std::vector<State> stream;
        model.sample_document_clock([&](const State& st) {
            ++samples;
            differ += !same_bits(st, model.state_at(st.t));
            differ += !same_bits(cursor.state(st.t), st);
            stream.push_back(st);
        });
        EXPECT_EQ(differ, 0) << s.name << " dim " << s.dim << " of " << samples << " samples";
        // Back and forth: every time its own answer.
        ExactModel::Cursor jumping(model);
        std::uniform_real_distribution<double> time(-0.1, s.duration + 0.1);
        std::vector<State> random_times;
        for (int k = 0; k < 20'000; ++k) {
            const double t = time(rng);
            ASSERT_TRUE(same_bits(jumping.state(t), model.state_at(t))) << "t = " << t;
            State at;
            at.t = t;
            random_times.push_back(at);
        }
        const double nan = std::nan("");
        EXPECT_TRUE(same_bits(jumping.state(nan), model.state_at(nan)));
        // positions(): the stream in blocks of any size, then times that
        // step back, repeat and include NaN.
        std::sort(random_times.begin(), random_times.begin() + 10'000,
                  [](const State& a, const State& b) { return a.t < b.t; });
        random_times[5'000].t = random_times[4'999].t;
        random_times[15'000].t = nan;
        for (const std::vector<State>* times : {&stream, &random_times}) {
            ExactModel::Cursor blocks(model);
            std::vector<Vec3> out(times->size());
            for (std::size_t begin = 0, size = 1; begin < times->size(); begin += size, size = size * 3 % 509 + 1)
                blocks.positions(std::span<const State>(*times).subspan(begin, std::min(size, times->size() - begin)),
                                 out.data() + begin);
            std::int64_t positions_differ = 0;
            for (std::size_t i = 0; i < times->size(); ++i)
                positions_differ +=
                    std::memcmp(out[i].data(), model.state_at((*times)[i].t).p.data(), 3 * sizeof(double)) != 0;
            EXPECT_EQ(positions_differ, 0) << s.name << " dim " << s.dim << " of " << times->size() << " times";
        }
    }
    EXPECT_GE(tails, 3);  // the tail's hop cache is exercised
}

TEST(ExactModelBounds, PositionIsContinuousThroughContacts) {
    const Scenario s = seed_3d();
    const ExactModel model(s);
    for (const WallContact& c : model.contacts()) {
        const State before = model.state_at(c.t - 1e-9);
        if (c.t > 0) {
            EXPECT_LT((before.p - c.p).norm(), 1e-9);
        }
        const State at = model.state_at(c.t);
        EXPECT_EQ(at.p, c.p);
        const double wall = c.side < 0 ? s.radius : s.room[c.axis] - s.radius;
        // A resolved contact is on the wall to the bit; a summed tail's
        // listed hop is where the tail's closed form puts its start.
        const auto tail = model.listed_tail_contacts();
        const bool listed = !tail.empty() && &c >= tail.data() && &c < tail.data() + tail.size();
        if (listed) EXPECT_NEAR(at.p[c.axis], wall, 1e-15);
        else EXPECT_EQ(at.p[c.axis], wall);
    }
}

TEST(ExactModelEnergy, ConstantBetweenContactsNonIncreasingAcross) {
    std::mt19937_64 rng(7);
    std::vector<Scenario> scenarios{seed_3d(), seed_2d()};
    for (int n = 0; n < 20; ++n) scenarios.push_back(random_room(rng, n, 0.0));
    for (const Scenario& s : scenarios) {
        const ExactModel model(s);
        const auto& contacts = model.contacts();
        for (const WallContact& c : contacts)
            EXPECT_LE(c.v_after.squaredNorm(), c.v_before.squaredNorm() * (1 + 1e-15));
        // Between two resolved contacts: constant.
        for (std::size_t k = 0; k + 1 < contacts.size(); ++k) {
            const double t0 = contacts[k].t, t1 = contacts[k + 1].t;
            if (t1 == t0) continue;
            const double e0 = energy(s, model.state_at(t0));
            for (const double f : {0.1, 0.5, 0.99})
                EXPECT_NEAR(energy(s, model.state_at(t0 + f * (t1 - t0))), e0, 1e-12 * (1 + std::abs(e0)));
        }
        // Over the whole run (Zeno tail and locks included): non-increasing.
        double previous = energy(s, model.state_at(0));
        for (double t = 0; t <= s.duration; t += 1e-3) {
            const double e = energy(s, model.state_at(t));
            EXPECT_LE(e, previous + 1e-12 * (1 + std::abs(previous))) << s.dim << " t " << t;
            previous = e;
        }
    }
}

TEST(ExactModelElastic, ZeroGravityConservesSpeedOverManyContacts) {
    const Vec3 v{0.7, -1.3, 0.9};
    const Scenario s = make_scenario(3, {1, 1, 1}, 0.05, {0.3, 0.6, 0.2}, v, Vec3::Zero(), 1, 1, 3500);
    const ExactModel model(s);
    ASSERT_GE(model.contacts().size(), 10'000u);
    EXPECT_FALSE(model.event_cap_hit());
    for (const WallContact& c : model.contacts()) {
        ASSERT_NEAR(c.v_after.norm(), v.norm(), 1e-12 * v.norm());
        ASSERT_EQ(c.v_after.cwiseAbs(), v.cwiseAbs());
    }
    const State end = model.state_at(s.duration);
    EXPECT_NEAR(end.v.norm(), v.norm(), 1e-12);
    expect_inside(s, end);
    EXPECT_FALSE(model.rest_time());
}

TEST(ExactModelAlphaZero, RestsAtFirstFloorImpact) {
    const double beta = 0.9;
    const Scenario s = drop(0.45, 9.81, 0.0, beta, {0.1, 0, 0});
    const ExactModel model(s);
    ASSERT_TRUE(model.rest_time());
    const WallContact& floor = model.contacts().front();
    EXPECT_EQ(floor.axis, 2);
    EXPECT_EQ(*model.rest_time(), floor.t);
    const State after = model.state_at(floor.t + 1);
    EXPECT_EQ(after.p[2], s.radius);
    EXPECT_EQ(after.v[2], 0.0);
    EXPECT_DOUBLE_EQ(after.v[0], 0.1 * beta);  // one contact: slides on at beta v
    // It slides into the x wall, which stops it (alpha = 0) and stays there.
    ASSERT_EQ(model.contacts().size(), 2u);
    EXPECT_EQ(model.contacts()[1].axis, 0);
    const State end = model.state_at(s.duration);
    EXPECT_EQ(end.v, Vec3::Zero());
    EXPECT_EQ(end.p, Vec3(0.95, 0.5, 0.05));
}

TEST(ExactModelDiagonalGravity, EndsRestingInCornerWithoutHanging) {
    const Scenario cases[] = {
        make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.5, 0.5}, {0.3, 0.2, 0.4}, {-0.3, -0.2, -9.81}, 0.8, 0.99, 60),
        make_scenario(3, {1, 2, 1}, 0.05, {0.5, 0.5, 0.5}, {0.3, 0.2, 0.4}, {2, -1, 3}, 0.9, 1.0, 60),
        make_scenario(2, {1, 1, 0}, 0.05, {0.5, 0.5, 0}, {1, 0, 0}, {-1, -1, 0}, 0.8, 0.9, 60),
        make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.5, 0.5}, {0.3, 0.2, 0.4}, {-0.3, -0.2, -9.81}, 0.0, 0.5, 60),
        // Corner Zeno with weak damping and a free axis: the hops must keep
        // shrinking below ulp(size) instead of being sustained by round-off.
        make_scenario(3, {1.85, 1.46, 0.53}, 0.05, {1.17, 0.05, 0.34}, {0.4, 0, -0.74}, {6.1, 7.9, 0}, 0.99, 0.32, 100),
    };
    for (const Scenario& s : cases) {
        const ExactModel model(s);
        EXPECT_FALSE(model.event_cap_hit());
        EXPECT_LT(model.contacts().size(), 100'000u);
        EXPECT_EQ(model.rest_time().has_value(), s.gravity[s.vertical_axis()] != 0);
        const State end = model.state_at(s.duration);
        EXPECT_EQ(end.v, Vec3::Zero());
        for (int i = 0; i < s.dim; ++i) {
            if (s.gravity[i] == 0) continue;  // stopped somewhere along a gravity-free axis
            EXPECT_EQ(end.p[i], s.gravity[i] < 0 ? s.radius : s.room[i] - s.radius) << "axis " << i;
        }
    }
}

TEST(ExactModel2D, Seed2dWorks) {
    const Scenario s = seed_2d();
    const ExactModel model(s);
    ASSERT_FALSE(model.contacts().empty());
    // It starts against the ceiling but not moving into it: no contact at 0.
    const WallContact& first = model.contacts().front();
    EXPECT_EQ(first.axis, 0);
    EXPECT_EQ(first.side, +1);
    EXPECT_NEAR(first.t, 0.45 / 0.3, 1e-12);
    for (const WallContact& c : model.contacts()) {
        EXPECT_LT(c.axis, 2);
        EXPECT_EQ(c.p[2], 0.0);
        EXPECT_EQ(c.v_after[2], 0.0);
    }
    EXPECT_EQ(model.apexes().front().t, 0.0);
    EXPECT_TRUE(model.rest_time());
    model.sample_document_clock([&](const State& st) {
        expect_inside(s, st);
        EXPECT_EQ(st.p[2], 0.0);
        EXPECT_EQ(st.v[2], 0.0);
    });
}

TEST(ExactModelSampling, DocumentClockRowsAndTimes) {
    for (const Scenario& s : {seed_3d(), seed_2d()}) {
        const ExactModel model(s);
        std::vector<State> rows;
        model.sample_document_clock([&](const State& st) { rows.push_back(st); });
        ASSERT_EQ(static_cast<std::int64_t>(rows.size()), document_step_count(s.dt, s.duration) + 1);
        double t = 0;
        for (const State& row : rows) {
            ASSERT_EQ(row.t, t);
            const State direct = model.state_at(t);
            ASSERT_EQ(row.p, direct.p);
            ASSERT_EQ(row.v, direct.v);
            t = t + s.dt;
        }
        EXPECT_LE(rows.back().t, model.horizon());
    }
}

TEST(ExactModelRoots, NoCancellationForFastBallInWeakGravity) {
    // Naive (-b + sqrt(b^2 - 4ac)) / 2a loses most digits here.
    const double u = 1e3, g = 1e-7, d = 0.45;
    const Scenario s = make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.5, 0.5}, {0, 0, u}, {0, 0, -g}, 0.8, 0.99, 1);
    const ExactModel model(s);
    ASSERT_FALSE(model.contacts().empty());
    const long double ul = u, gl = g, dl = d;
    const long double expected = 2 * dl / (ul + std::sqrt(ul * ul - 2 * gl * dl));
    EXPECT_NEAR(model.contacts().front().t, static_cast<double>(expected), 1e-15 * static_cast<double>(expected));
}

TEST(ExactModelRoots, WallOutOfReachIsNeverHit) {
    // Rises 0.1 m at most: never reaches the ceiling 0.45 m above.
    const double g = 9.81, u = std::sqrt(2 * g * 0.1);
    const Scenario s = make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.5, 0.5}, {0, 0, u}, {0, 0, -g}, 0.8, 0.99, 5);
    const ExactModel model(s);
    ASSERT_FALSE(model.contacts().empty());
    EXPECT_EQ(model.contacts().front().side, -1);
    EXPECT_NEAR(model.apexes().front().height, 0.6, 1e-12);
}

TEST(ExactModelCap, FlagsTheEventCap) {
    const Scenario s = make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.5, 0.5}, {1, 0, 0}, Vec3::Zero(), 1, 1, 100);
    const ExactModel model(s, 10);
    EXPECT_TRUE(model.event_cap_hit());
    EXPECT_EQ(model.contacts().size(), 10u);
    EXPECT_FALSE(ExactModel(s).event_cap_hit());
}

TEST(ExactModelRest, SolveDoesNotDependOnDurationOnceAtRest) {
    Scenario s = seed_3d();
    const ExactModel short_run(s);
    s.duration = 1e6;
    const ExactModel long_run(s);
    EXPECT_EQ(long_run.contacts().size(), short_run.contacts().size());
    EXPECT_EQ(long_run.rest_time(), short_run.rest_time());
    EXPECT_EQ(long_run.state_at(1e6).p, short_run.state_at(42).p);
}

TEST(ExactModelRest, StartingAtRestOnTheFloor) {
    const Scenario s = drop(0.0, 9.81, 0.8);
    const ExactModel model(s);
    EXPECT_TRUE(model.contacts().empty());
    EXPECT_TRUE(model.apexes().empty());
    EXPECT_EQ(model.rest_time(), 0.0);
    EXPECT_EQ(model.state_at(5).p, s.position);
}

}  // namespace
}  // namespace bouncecheck

namespace bouncecheck {
namespace {

// The bundled Earth drop (alpha 0.7, dt 0.01): its Zeno tail is summed from
// the first impact, and every hop of it is listed from the closed form.
TEST(ExactModelZeno, EarthDropListsTheSummedTailsBounces) {
    const Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/earth-drop.toml");
    const ExactModel model(s);
    const double g = 9.81, h = 1.0, alpha = s.alpha, r = s.radius;
    const double v0 = std::sqrt(2 * g * h), t1 = std::sqrt(2 * h / g);
    EXPECT_EQ(model.summed_tail_contacts(), -1);
    const auto& apexes = model.apexes();
    ASSERT_GE(apexes.size(), 8u);
    for (std::size_t k = 0; k < apexes.size(); ++k)
        EXPECT_NEAR(apexes[k].height, r + h * std::pow(alpha, 2.0 * k), 1e-9) << "apex " << k;
    const auto& contacts = model.contacts();
    ASSERT_GE(contacts.size(), 8u);
    double t = t1;
    for (std::size_t k = 0; k < contacts.size(); ++k) {
        EXPECT_NEAR(contacts[k].t, t, 1e-12) << "contact " << k;
        EXPECT_NEAR(-contacts[k].v_before[2], v0 * std::pow(alpha, k), 1e-12 * v0);
        EXPECT_NEAR(contacts[k].v_after[2], v0 * std::pow(alpha, k + 1), 1e-12 * v0);
        t += 2 * v0 * std::pow(alpha, k + 1) / g;
    }
    // Every bounce more than a step long is listed: the first unlisted hop is shorter.
    const double last_flight = 2 * v0 * std::pow(alpha, contacts.size()) / g;
    EXPECT_LT(last_flight, s.dt);
}

}  // namespace
}  // namespace bouncecheck
