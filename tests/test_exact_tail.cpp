// exact's summed Zeno tail lists its bounces: contacts() and apexes() hold the
// tail's hops from their closed forms (ExactModel::listed_tail_contacts), the
// infinite rest stays summed_tail_contacts() = -1, and the states are the
// ones exact gave before it listed them.
#include "exact/exact_model.h"
#include "tests/support/scenarios.h"
#include "exact/exact_simulator.h"
#include "metrics/summary.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace bouncecheck {
namespace {

using test::make_scenario;

constexpr double kG = 9.81, kH = 1.0, kAlpha = 0.7, kRadius = 0.1;

// The classic Earth drop: a 2 m room, a 10 cm ball whose bottom is 1 m above
// the floor, from rest (or sliding at vx), alpha 0.7, dt 0.01, 3 s.
Scenario earth_drop(int dim, double beta, double vx = 0, double duration = 3.0) {
    const Vec3 room = dim == 3 ? Vec3{2, 2, 2} : Vec3{2, 2, 0};
    const Vec3 p = dim == 3 ? Vec3{1, 1, kRadius + kH} : Vec3{1, kRadius + kH, 0};
    const Vec3 g = dim == 3 ? Vec3{0, 0, -kG} : Vec3{0, -kG, 0};
    return make_scenario(dim, room, kRadius, p, {vx, 0, 0}, g, kAlpha, beta, duration, 0.01);
}

// The drop in closed form, in long double: first impact at t1 = sqrt(2 h / g),
// contact n at t1 + 2 t1 alpha (1 - alpha^n) / (1 - alpha), the hop after it
// rising h alpha^(2 (n + 1)) at its middle, t1 alpha^(n + 1) later.
long double t1() { return std::sqrt(2.0L * kH / kG); }
long double contact_time(int n) { return t1() + 2 * t1() * kAlpha * (1 - std::pow(0.7L, n)) / (1 - 0.7L); }
long double apex_time(int k) { return k == 0 ? 0.0L : contact_time(k - 1) + t1() * std::pow(0.7L, k); }
long double apex_rise(int k) { return kH * std::pow(0.7L, 2 * k); }

bool in_span(const WallContact& c, std::span<const WallContact> span) {
    return !span.empty() && &c >= span.data() && &c < span.data() + span.size();
}

TEST(ExactTail, EarthDropListsEveryBounceAStepLong) {
    for (const int dim : {2, 3}) {
        for (const double beta : {0.99, 1.0}) {
            SCOPED_TRACE(testing::Message() << "dim " << dim << " beta " << beta);
            const Scenario s = earth_drop(dim, beta);
            const int z = dim - 1;
            const ExactModel model(s);
            EXPECT_EQ(model.summed_tail_contacts(), -1);
            ASSERT_TRUE(model.rest_time());
            EXPECT_NEAR(*model.rest_time(), static_cast<double>(t1() * (1 + 0.7L) / (1 - 0.7L)), 1e-12);

            const auto& apexes = model.apexes();
            ASSERT_GE(apexes.size(), 8u);
            double worst_height = 0, worst_apex_t = 0;
            for (std::size_t k = 0; k < apexes.size(); ++k) {
                const double height = static_cast<double>(kRadius + apex_rise(static_cast<int>(k)));
                EXPECT_NEAR(apexes[k].height, height, 1e-9) << "apex " << k;
                EXPECT_NEAR(apexes[k].t, static_cast<double>(apex_time(static_cast<int>(k))), 1e-12) << "apex " << k;
                worst_height = std::max(worst_height, std::abs(apexes[k].height - height));
                worst_apex_t =
                    std::max(worst_apex_t, std::abs(apexes[k].t - static_cast<double>(apex_time(static_cast<int>(k)))));
            }
            const auto& contacts = model.contacts();
            ASSERT_GE(contacts.size(), 8u);
            // The first impact is resolved, every later one is the summed tail's.
            ASSERT_EQ(model.listed_tail_contacts().size(), contacts.size() - 1);
            EXPECT_EQ(model.listed_tail_apexes().size(), apexes.size() - 1);
            double worst_t = 0;
            for (std::size_t n = 0; n < contacts.size(); ++n) {
                const WallContact& c = contacts[n];
                EXPECT_EQ(c.axis, z);
                EXPECT_EQ(c.side, -1);
                EXPECT_NEAR(c.t, static_cast<double>(contact_time(static_cast<int>(n))), 1e-12) << "contact " << n;
                worst_t = std::max(worst_t, std::abs(c.t - static_cast<double>(contact_time(static_cast<int>(n)))));
                EXPECT_NEAR(c.p[z], kRadius, 1e-15) << "contact " << n;
                // Between consecutive contacts there is exactly one apex.
                if (n + 1 < apexes.size()) {
                    EXPECT_GT(apexes[n + 1].t, c.t);
                    if (n + 1 < contacts.size()) {
                        EXPECT_LT(apexes[n + 1].t, contacts[n + 1].t);
                    }
                }
            }
            // Every hop at least a step long is listed: the first one left
            // out (the hop after the last listed contact) is shorter.
            const double unlisted_flight = static_cast<double>(2 * t1() * std::pow(0.7L, contacts.size()));
            EXPECT_LT(unlisted_flight, s.dt);
            // Rest comes after every listed bounce.
            EXPECT_LT(contacts.back().t, *model.rest_time());
            EXPECT_LT(apexes.back().t, *model.rest_time());
            std::printf("[ info ] Earth drop dim %d beta %g: %zu contacts + inf, %zu apexes; worst apex height %.3g m, "
                        "apex time %.3g s, contact time %.3g s\n",
                        dim, beta, contacts.size(), apexes.size(), worst_height, worst_apex_t, worst_t);
        }
    }
}

TEST(ExactTail, ListedContactsScaleByAlphaAndBeta) {
    for (const int dim : {2, 3}) {
        for (const double beta : {0.99, 1.0, 0.5}) {
            SCOPED_TRACE(testing::Message() << "dim " << dim << " beta " << beta);
            // Sliding slowly: the tail is summed at the first impact and its
            // travel (~0.05 m) stays clear of the side walls.
            const Scenario s = earth_drop(dim, beta, 0.02);
            const int z = dim - 1;
            const ExactModel model(s);
            const auto tail = model.listed_tail_contacts();
            ASSERT_GE(tail.size(), 8u);
            const WallContact& first = model.contacts().front();
            ASSERT_FALSE(in_span(first, tail));
            double worst_normal = 0, worst_tangential = 0;
            const WallContact* previous = &first;
            double x = first.p[0];
            for (const WallContact& c : tail) {
                // Into the wall before, out of it after.
                EXPECT_LT(c.v_before[z], 0);
                EXPECT_GT(c.v_after[z], 0);
                const double normal = -c.v_after[z] / c.v_before[z];
                const double tangential = c.v_after[0] / c.v_before[0];
                EXPECT_NEAR(normal, kAlpha, 1e-12) << "t " << c.t;
                EXPECT_NEAR(tangential, beta, 1e-12) << "t " << c.t;
                worst_normal = std::max(worst_normal, std::abs(normal - kAlpha));
                worst_tangential = std::max(worst_tangential, std::abs(tangential - beta));
                // The flight from the previous contact mirrors its speed
                // along the normal and keeps the tangential velocity.
                EXPECT_NEAR(c.v_before[z], -previous->v_after[z], 1e-12 * std::abs(previous->v_after[z]));
                EXPECT_NEAR(c.v_before[0], previous->v_after[0], 1e-15);
                EXPECT_NEAR(c.t - previous->t, 2 * previous->v_after[z] / kG, 1e-12);
                // Tangential travel: the sliding speed over the hop.
                x += previous->v_after[0] * (c.t - previous->t);
                EXPECT_NEAR(c.p[0], x, 1e-12);
                for (int j = 0; j < dim; ++j) {
                    if (j != 0 && j != z) {
                        EXPECT_EQ(c.v_after[j], 0.0);
                    }
                }
                previous = &c;
            }
            std::printf("[ info ] dim %d beta %g: %zu tail contacts, normal ratio within %.3g of alpha, tangential "
                        "within %.3g of beta\n",
                        dim, beta, tail.size(), worst_normal, worst_tangential);
        }
    }
}

TEST(ExactTail, ListedBouncesAreTheStatesAtTheirInstants) {
    for (const Scenario& s : {earth_drop(3, 0.99, 0.02), earth_drop(2, 1.0, 0.02)}) {
        const int z = s.dim - 1;
        const ExactModel model(s);
        ASSERT_FALSE(model.listed_tail_contacts().empty());
        for (const WallContact& c : model.listed_tail_contacts()) {
            // At a contact instant state_at gives the state after the contact.
            const State at = model.state_at(c.t);
            EXPECT_EQ(at.p, c.p) << "t " << c.t;
            EXPECT_EQ(at.v, c.v_after) << "t " << c.t;
            const State before = model.state_at(c.t - 1e-9 * (c.v_before.norm() + 1e-3));
            EXPECT_LT(before.v[z], 0) << "t " << c.t;
        }
        for (const Apex& a : model.listed_tail_apexes()) {
            const State at = model.state_at(a.t);
            EXPECT_NEAR(at.p[z], a.height, 1e-12) << "t " << a.t;
            EXPECT_NEAR(at.v[z], 0, 1e-12) << "t " << a.t;
        }
    }
}

TEST(ExactTail, OnlyBouncesWithinTheDurationAreListed) {
    // The run ends at 1.5 s, long before the accumulation at 2.56 s: the
    // tail is summed at the first impact (0.45 s), and only its bounces up
    // to 1.5 s (the second at 1.08 s; the third, 1.52 s, is past it) are listed.
    const Scenario s = earth_drop(3, 0.99, 0, 1.5);
    const ExactModel model(s);
    EXPECT_EQ(model.summed_tail_contacts(), -1);
    EXPECT_FALSE(model.rest_time());
    std::size_t expected_contacts = 0, expected_apexes = 0;
    while (contact_time(static_cast<int>(expected_contacts)) <= 1.5L) ++expected_contacts;
    while (apex_time(static_cast<int>(expected_apexes)) <= 1.5L) ++expected_apexes;
    ASSERT_GE(expected_contacts, 2u);
    EXPECT_EQ(model.contacts().size(), expected_contacts);
    EXPECT_EQ(model.apexes().size(), expected_apexes);
    for (const WallContact& c : model.contacts()) EXPECT_LE(c.t, s.duration);
    for (const Apex& a : model.apexes()) EXPECT_LE(a.t, s.duration);
}

TEST(ExactTail, CeilingAndSideWallTails) {
    // Gravity up: the tail is on the ceiling, its apexes are the bottoms of
    // the hops, hi - u_k^2 / (2 g).
    {
        const double g = 3.0, alpha = 0.6;
        const Scenario s = make_scenario(2, {1, 1, 0}, 0.05, {0.3, 0.4, 0}, {0.1, 0.2, 0}, {0, g, 0}, alpha, 0.9, 5, 0.005);
        const ExactModel model(s);
        const auto tail = model.listed_tail_contacts();
        const auto bottoms = model.listed_tail_apexes();
        ASSERT_GE(tail.size(), 5u);
        ASSERT_GE(bottoms.size(), 5u);
        const WallContact& start = *(tail.data() - 1);  // the resolved bounce that starts the tail
        EXPECT_EQ(start.side, +1);
        double u = start.v_after[1];
        ASSERT_LT(u, 0);
        for (std::size_t k = 0; k < bottoms.size(); ++k) {
            EXPECT_NEAR(bottoms[k].height, 0.95 - u * u / (2 * g), 1e-12) << "bottom " << k;
            u *= alpha;
        }
        for (const WallContact& c : tail) {
            EXPECT_EQ(c.side, +1);
            EXPECT_GT(c.v_before[1], 0);
            EXPECT_NEAR(-c.v_after[1] / c.v_before[1], alpha, 1e-12);
            EXPECT_NEAR(c.v_after[0] / c.v_before[0], 0.9, 1e-12);
        }
    }
    // Gravity along -x only: the tail is on the left wall; with no vertical
    // gravity nothing has an apex, so the tail lists contacts only.
    {
        const Scenario s =
            make_scenario(2, {1, 1, 0}, 0.05, {0.3, 0.4, 0}, {0, 0.2, 0}, {-4, 0, 0}, 0.75, 0.9, 5, 0.005);
        const ExactModel model(s);
        EXPECT_EQ(model.summed_tail_contacts(), -1);
        ASSERT_GE(model.listed_tail_contacts().size(), 5u);
        EXPECT_TRUE(model.listed_tail_apexes().empty());
        for (const WallContact& c : model.listed_tail_contacts()) {
            EXPECT_EQ(c.axis, 0);
            EXPECT_EQ(c.side, -1);
            EXPECT_NEAR(-c.v_after[0] / c.v_before[0], 0.75, 1e-12);
        }
    }
}

TEST(ExactTail, ListingIsCapped) {
    // alpha 0.999: thousands of hops above any cut; at most
    // kMaxListedTailHops are listed, and the run still ends summed.
    const Scenario s = make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.5, 0.95}, {0, 0, 0}, {0, 0, -kG}, 0.999, 0.99,
                                     1000, 0.01);
    const ExactModel model(s);
    EXPECT_EQ(model.summed_tail_contacts(), -1);
    EXPECT_EQ(static_cast<std::int64_t>(model.listed_tail_contacts().size()), ExactModel::kMaxListedTailHops);
    EXPECT_LE(static_cast<std::int64_t>(model.listed_tail_apexes().size()), ExactModel::kMaxListedTailHops);
    EXPECT_EQ(model.contacts().size(), model.listed_tail_contacts().size() + 1);
    ASSERT_TRUE(model.rest_time());
    EXPECT_LT(model.contacts().back().t, *model.rest_time());
}

// What the simulator hands over: the summary counts the listed contacts,
// keeps the first kKeptApexes apexes, and still says the rest is unbounded.
TEST(ExactTail, SimulatorHandsTheListedBouncesOver) {
    const Scenario s = earth_drop(3, 0.99);
    const ExactModel model(s);
    const auto simulator = make_exact_simulator();
    const SimulatorSummary r = record_run(*simulator, s);
    EXPECT_TRUE(r.contacts_unbounded);
    EXPECT_EQ(r.contacts, static_cast<std::int64_t>(model.contacts().size()));
    EXPECT_EQ(r.floor_contacts, r.contacts);
    EXPECT_EQ(r.apex_count, static_cast<std::int64_t>(model.apexes().size()));
    ASSERT_EQ(r.apexes.size(), std::min(model.apexes().size(), kKeptApexes));
    for (std::size_t k = 0; k < r.apexes.size(); ++k) EXPECT_EQ(r.apexes[k].height, model.apexes()[k].height);
    ASSERT_EQ(r.contact_events.size(), model.contacts().size());
    for (std::size_t n = 1; n < r.contact_events.size(); ++n)
        EXPECT_NEAR(r.contact_events[n].normal_coefficient, kAlpha, 1e-12) << "contact " << n;
    ASSERT_TRUE(r.rest_time);
    EXPECT_EQ(*r.rest_time, *model.rest_time());
}

// FNV-1a over the bits of every document-clock state (t, then the used
// coordinates of p and v): the states exact gave before it listed the tail's
// bounces (hashes of its trajectory files then, which parse back bit for bit).
std::uint64_t state_hash(const ExactModel& model, int dim) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    const auto add = [&](double x) {
        unsigned char bytes[sizeof x];
        std::memcpy(bytes, &x, sizeof x);
        for (const unsigned char b : bytes) h = (h ^ b) * 0x100000001b3ull;
    };
    model.sample_document_clock([&](const State& st) {
        add(st.t);
        for (int i = 0; i < dim; ++i) add(st.p[i]);
        for (int i = 0; i < dim; ++i) add(st.v[i]);
    });
    return h;
}

TEST(ExactTail, StatesAreUnchanged) {
    struct Case {
        const char* name;
        Scenario s;
        std::uint64_t hash;
    };
    const Case cases[] = {
        // scenarios/seed-2d.toml and seed-3d.toml
        {"seed-2d",
         make_scenario(2, {1, 1, 0}, 0.05, {0.5, 0.95, 0}, {0.3, 0, 0}, {0, -0.0981, 0}, 0.8, 0.99, 50),
         0x66e12be229732cbbull},
        {"seed-3d",
         make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.95, 0.5}, {0.3, 0.1, 0.2}, {0, 0, -0.0981}, 0.8, 0.99, 42),
         0xb9864819aa2e01d2ull},
        {"earth drop 3D", earth_drop(3, 0.99), 0x287ae1c80a1d79b9ull},
        {"earth drop 2D sliding, beta 1", earth_drop(2, 1.0, 0.3), 0xd266c6098419de69ull},
        {"ceiling", make_scenario(2, {1, 1, 0}, 0.05, {0.3, 0.4, 0}, {0.1, 0.2, 0}, {0, 3, 0}, 0.6, 0.9, 5, 0.005),
         0x28c6d20606eab2f2ull},
        {"side wall", make_scenario(2, {1, 1, 0}, 0.05, {0.3, 0.4, 0}, {0, 0.2, 0}, {-4, 0, 0}, 0.75, 0.9, 5, 0.005),
         0x787c5a000decdf34ull},
        {"slide", make_scenario(3, {1, 1, 1}, 0.05, {0.5, 0.5, 0.5}, {0.05, 0, 0}, {0, 0, -kG}, 0.8, 1.0, 20, 0.01),
         0xb63e6e193982f750ull},
    };
    for (const Case& c : cases) {
        const ExactModel model(c.s);
        EXPECT_EQ(state_hash(model, c.s.dim), c.hash) << c.name;
    }
}

}  // namespace
}  // namespace bouncecheck
