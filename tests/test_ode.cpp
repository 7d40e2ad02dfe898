// The ODE adapter against the exact model, and one test per known ODE trap:
// each runs the engine with the trap's default (or the samples' usual value)
// put back through ode::Tuning and checks what it does to the ball, next to
// the adapter's chosen setting.
#include "engines/ode/ode_adapter.h"
#include "exact/exact_model.h"
#include "metrics/summary.h"
#include "scenarios/loader.h"
#include "tests/support/engine_run.h"
#include "tests/support/cli.h"
#include "tests/support/engine_tests.h"
#include "tests/support/test_directory.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace bouncecheck {
namespace {

using ode::Tuning;
using test::setting;

Scenario seed(int dim) {
    // The bundled file's [engines] tables (calibrated friction) are dropped:
    // each test sets the engine options it is about.
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + (dim == 3 ? "/seed-3d.toml" : "/seed-2d.toml"));
    s.engines.clear();
    return s;
}

Scenario seed_at(int dim, double dt, double duration) {
    Scenario s = seed(dim);
    s.dt = dt;
    s.duration = duration;
    return s;
}

// The document's semantics inside the engine: mu = 0, beta once per contact.
Scenario with_per_contact(Scenario s) {
    EngineOptions opt;
    opt.tangential_model = TangentialModel::per_contact;
    s.engines["ode"] = opt;
    return s;
}

// A 2D drop that reaches the floor before any side wall, with friction mu.
Scenario friction_drop(double mu, double dt = 1e-3) {
    Scenario s = seed_at(2, dt, 5.0);
    s.position = {0.1, 0.95, 0};
    s.velocity = {0.15, 0, 0};  // x = 0.74 at the floor; slides through the contact step
    EngineOptions opt;
    opt.friction = mu;
    s.engines["ode"] = opt;
    return s;
}

// Runs `s` through the shared run() path with `tuning` (chosen() unless given).
test::SimulatorRun run_ode(const Scenario& s, const Tuning& tuning = Tuning::chosen()) {
    const auto sim = ode::make_simulator(tuning);
    test::SimulatorRun run;
    run.summary = record_run(*sim, s);
    // States: step a second, identical world directly (same tuning, same options).
    std::vector<Setting> ignored;
    const auto world = ode::build_world(s, s.engine_options("ode"), tuning, ignored);
    State st{0.0, s.position, s.velocity};
    run.states.push_back(st);
    for (std::int64_t i = 0; i < run.summary.steps; ++i) {
        world->step();
        world->read(st);
        st.t = static_cast<double>(i + 1) * s.dt;
        run.states.push_back(st);
    }
    return run;
}

// A contact on wall (axis, side) seen in the stream: index k of the first
// state after it (velocity into the wall at k - 1, not into it at k).
struct StreamContact {
    std::size_t k;
    double t;        // t_k
    double v_in;     // normal velocity component at k - 1
    double v_out;    // at k
    double restitution() const { return -v_out / v_in; }
};

std::vector<StreamContact> stream_contacts(const std::vector<State>& states, int axis, int side) {
    std::vector<StreamContact> out;
    for (std::size_t k = 1; k < states.size(); ++k) {
        const double a = states[k - 1].v[axis], b = states[k].v[axis];
        const bool hit = side < 0 ? (a < 0 && b >= 0) : (a > 0 && b <= 0);
        if (hit) out.push_back({k, states[k].t, a, b});
    }
    return out;
}

std::vector<StreamContact> floor_contacts(const Scenario& s, const std::vector<State>& states) {
    return stream_contacts(states, s.vertical_axis(), -1);
}

std::vector<WallContact> exact_floor_contacts(const Scenario& s, const ExactModel& exact) {
    std::vector<WallContact> out;
    for (const WallContact& c : exact.contacts())
        if (c.axis == s.vertical_axis() && c.side < 0) out.push_back(c);
    return out;
}

double max_speed(const std::vector<State>& states) {
    double m = 0;
    for (const State& st : states) m = std::max(m, st.v.norm());
    return m;
}

// Highest vertical excursion above resting height (centre at r) after time t0.
double max_hop_after(const Scenario& s, const std::vector<State>& states, double t0) {
    double m = -std::numeric_limits<double>::infinity();
    for (const State& st : states)
        if (st.t >= t0) m = std::max(m, st.p[s.vertical_axis()] - s.radius);
    return m;
}

// ---------------------------------------------------------------------------
// Against exact at dt = 1e-3.
//
// ODE integrates semi-implicitly (v += g dt, then p += v dt) and finds a
// contact only once the sphere overlaps a plane, at the start of the next
// step; the bounce then sets the outgoing normal speed to alpha x the incoming
// one in that step. So:
// - a contact is seen in the stream 1 to 2 steps after the exact instant, plus
//   the integrator's drift g t dt / 2 / v (half a step over the first fall):
//   tolerance 3 dt;
// - an apex is off by the integrator's O(v dt) (v dt / 2 per flight) plus the
//   penetration at the bounce (at most v dt), compounding over bounces:
//   tolerance 2 v_max dt per apex (v_max the largest speed, ~0.45 m/s: 0.9 mm);
// - the restitution measured from the stream is alpha to round-off.

class OdeVsExact : public ::testing::TestWithParam<int> {};

TEST_P(OdeVsExact, FirstFloorContactApexesAndRestitution) {
    const int dim = GetParam();
    const Scenario s = with_per_contact(seed_at(dim, 1e-3, 15.0));
    const ExactModel exact(s);
    const auto run = run_ode(s);
    ASSERT_EQ(run.summary.status, RunStatus::ok) << run.summary.reason;

    const auto ode_floor = floor_contacts(s, run.states);
    const auto exact_floor = exact_floor_contacts(s, exact);
    ASSERT_GE(ode_floor.size(), 2u);
    ASSERT_GE(exact_floor.size(), 2u);
    const double v_max = max_speed(run.states);

    const double contact_error = ode_floor[0].t - exact_floor[0].t;
    std::printf("dim %d: first floor contact ode %.6f exact %.6f (diff %.2f dt)\n", dim, ode_floor[0].t,
                exact_floor[0].t, contact_error / s.dt);
    EXPECT_NEAR(ode_floor[0].t, exact_floor[0].t, 3 * s.dt);

    ASSERT_GE(run.summary.apexes.size(), 3u);
    ASSERT_GE(exact.apexes().size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
        std::printf("dim %d: apex %zu ode %.6f exact %.6f (diff %.2e)\n", dim, i, run.summary.apexes[i].height,
                    exact.apexes()[i].height, run.summary.apexes[i].height - exact.apexes()[i].height);
        EXPECT_NEAR(run.summary.apexes[i].height, exact.apexes()[i].height, 2 * v_max * s.dt) << "apex " << i;
    }

    // Restitution at the first floor contacts: outgoing over incoming normal speed.
    for (std::size_t i = 0; i < 2; ++i) {
        std::printf("dim %d: floor contact %zu restitution %.15f\n", dim, i, ode_floor[i].restitution());
        EXPECT_NEAR(ode_floor[i].restitution(), s.alpha, 1e-12);
    }
}

INSTANTIATE_TEST_SUITE_P(OdeVsExact, OdeVsExact, ::testing::Values(2, 3),
                         [](const auto& info) { return std::string(info.param == 2 ? "Seed2d" : "Seed3d"); });

// ---------------------------------------------------------------------------
// Seeds at their own dt through the real path (the CSV of --trajectories).

class OdeSeedRun : public ::testing::TestWithParam<int> {};

TEST_P(OdeSeedRun, CompletesInsideTheRoomAndBounces) {
    const int dim = GetParam();
    const Scenario s = seed(dim);
    const auto run = test::run_simulator("ode", s);
    ASSERT_EQ(run.summary.status, RunStatus::ok) << run.summary.reason;
    EXPECT_EQ(run.summary.steps, static_cast<std::int64_t>(run.states.size()) - 1);
    EXPECT_GE(run.summary.floor_contacts, 5);
    EXPECT_GE(floor_contacts(s, run.states).size(), 5u);
    // Inside the room: a contact is found once the sphere overlaps the wall,
    // so it can be inside by at most one step of travel.
    const double tol = max_speed(run.states) * s.dt + 1e-12;
    for (const State& st : run.states)
        for (int i = 0; i < s.dim; ++i) {
            ASSERT_GE(st.p[i], s.radius - tol) << "t " << st.t << " axis " << i;
            ASSERT_LE(st.p[i], s.room[i] - s.radius + tol) << "t " << st.t << " axis " << i;
        }
    EXPECT_EQ(setting(run.summary, "precision"), "double");
    EXPECT_EQ(setting(run.summary, "stepper"), "dWorldStep");
}

INSTANTIATE_TEST_SUITE_P(OdeSeedRun, OdeSeedRun, ::testing::Values(2, 3),
                         [](const auto& info) { return std::string(info.param == 2 ? "Seed2d" : "Seed3d"); });

// 2D through ODE's planar joint: the body stays in ODE's z = 0 plane and only
// turns about z.
TEST(OdePlanar, TwoDimensionalBallStaysInThePlane) {
    Scenario s = seed_at(2, 0.03, 50.0);
    EngineOptions friction;
    friction.friction = 0.05;  // friction spins the ball: a tilt would show in x/y angular velocity
    s.engines["ode"] = friction;
    std::vector<Setting> settings;
    const auto world = ode::build_world(s, s.engine_options("ode"), Tuning::chosen(), settings);
    double max_z = 0, max_tilt = 0, max_spin = 0;
    for (int i = 0; i < 1667; ++i) {
        world->step();
        max_z = std::max(max_z, std::abs(world->engine_position()[2]));
        const Vec3 w = world->engine_angular_velocity();
        max_tilt = std::max({max_tilt, std::abs(w[0]), std::abs(w[1])});
        max_spin = std::max(max_spin, std::abs(w[2]));
    }
    EXPECT_LT(max_z, 1e-12);
    EXPECT_LT(max_tilt, 1e-12);
    EXPECT_GT(max_spin, 1e-3);  // friction did act, about the plane's normal
}

// ---------------------------------------------------------------------------
// Traps.

// bounce_vel: ODE bounces only if the incoming speed exceeds it. An
// uninitialised dContact leaves it garbage; samples use ~0.1 m/s, which at the
// seed's speeds (0.42 m/s at the first impact, x 0.8 per bounce) ends the
// bouncing after 8 bounces (t ~ 31 s) while the exact ball bounces on.
TEST(OdeTraps, BounceVelocityZeroKeepsTheBallBouncing) {
    const Scenario s = with_per_contact(seed_at(2, 0.03, 36.0));
    const ExactModel exact(s);
    const auto chosen = run_ode(s);
    EXPECT_EQ(setting(chosen.summary, "bounce_vel"), "0");
    Tuning sample;
    sample.bounce_vel = 0.1;
    const auto trap = run_ode(s, sample);
    // exact lists its contacts up to the start of its summed Zeno tail.
    const auto exact_floor = exact_floor_contacts(s, exact);
    const double until = exact_floor.back().t + 0.5;
    const auto count_until = [until](const std::vector<StreamContact>& cs) {
        return static_cast<std::size_t>(
            std::count_if(cs.begin(), cs.end(), [until](const StreamContact& c) { return c.t < until; }));
    };
    const auto exact_n = exact_floor.size();
    const auto chosen_n = count_until(floor_contacts(s, chosen.states));
    const auto trap_n = count_until(floor_contacts(s, trap.states));
    const double trap_last = trap.states.back().p[1] - s.radius, chosen_top = max_hop_after(s, chosen.states, 32.0);
    std::printf("floor contacts until %.2f s: exact %zu, ode %zu, ode with bounce_vel 0.1: %zu (last height %.2e m; "
                "ode's highest hop after 32 s %.3e m)\n",
                until, exact_n, chosen_n, trap_n, trap_last, chosen_top);
    EXPECT_EQ(chosen_n, exact_n);
    EXPECT_LE(trap_n + 2, exact_n);
    EXPECT_LT(std::abs(trap.states.back().v[1]), 1e-9);  // at rest on the floor
    EXPECT_GT(chosen_top, 1e-3);                         // still bouncing
}

// WallContact CFM: with ODE's world CFM 1e-5 the contact is soft. The LCP
// diagonal grows by CFM/dt relative to 1/m, so at dt = 1e-3 and 1 kg the
// normal impulse falls ~1% short: restitution ~0.78 instead of 0.8.
TEST(OdeTraps, ContactCfmZeroGivesRestitutionAlpha) {
    const Scenario s = seed_at(3, 1e-3, 6.0);
    const auto chosen = run_ode(s);
    EXPECT_EQ(setting(chosen.summary, "contact_softness").substr(0, 10), "soft_cfm 0");
    Tuning def;
    def.contact_soft_cfm = false;
    def.world_cfm = 1e-5;  // ODE's default
    const auto trap = run_ode(s, def);
    const double e_chosen = floor_contacts(s, chosen.states).at(0).restitution();
    const double e_trap = floor_contacts(s, trap.states).at(0).restitution();
    std::printf("restitution at the first floor contact: CFM 0 %.12f, world CFM 1e-5 %.12f\n", e_chosen, e_trap);
    EXPECT_NEAR(e_chosen, s.alpha, 1e-12);
    EXPECT_LT(e_trap, s.alpha - 0.01);
}

// WallContact ERP and max correcting velocity: ODE pushes an overlapping sphere
// out at ERP x depth / dt, capped by the max correcting velocity (default
// infinity): speed from nowhere. A bounce never triggers it (the overlap of
// one step is at most v dt, so 0.2 v < alpha v), but any deeper overlap does:
// here a ball at rest 1 cm inside the floor is thrown 2 cm up. In the seeds
// the only difference is where the ball finally rests (see SurfaceLayerZero).
TEST(OdeTraps, NoPenetrationPushOutAddsNoEnergy) {
    Scenario s = seed_at(2, 0.03, 10.0);
    s.position = {0.5, s.radius - 0.01, 0};  // 1 cm overlap, at rest
    s.velocity = {0, 0, 0};
    const auto highest = [&](const Tuning& t) {
        std::vector<Setting> settings;
        const auto world = ode::build_world(s, {}, t, settings);
        double top = -1;
        State st;
        for (int i = 0; i < 300; ++i) {
            world->step();
            world->read(st);
            top = std::max(top, st.p[1] - s.radius);
        }
        return top;
    };
    Tuning def;
    def.contact_soft_erp = false;  // world ERP 0.2, ODE's default
    def.max_correcting_vel = std::numeric_limits<double>::infinity();
    const double top_chosen = highest(Tuning::chosen()), top_default = highest(def);
    std::printf("ball at rest 1 cm inside the floor, highest point above contact: ERP 0 / max vel 0 %.3e m, "
                "ERP 0.2 / max vel inf %.3e m\n",
                top_chosen, top_default);
    EXPECT_LE(top_chosen, -0.01 + 1e-12);  // no speed gained: it stays where it was
    EXPECT_GT(top_default, 0.01);          // thrown out of the floor and up
    Tuning capped = def;
    capped.max_correcting_vel = 0;  // the cap alone also stops it
    EXPECT_LE(highest(capped), -0.01 + 1e-12);
    const auto run = run_ode(seed(2));
    EXPECT_EQ(setting(run.summary, "contact_max_correcting_vel"), "0");
    EXPECT_NE(setting(run.summary, "contact_softness").find("soft_erp 0 (dContactSoftERP)"), std::string::npos);
}

// Surface layer: ODE tolerates this much overlap before its ERP push-out acts.
// With contact ERP 0 it is inert (the run is bit-identical with the samples'
// 1 mm). With ODE's ERP 0.2 and layer 0 the seed's ball ends resting exactly
// on the floor; a 1 mm layer leaves it where its last bounce left it, inside.
TEST(OdeTraps, SurfaceLayerZero) {
    const Scenario s = seed_at(2, 0.03, 50.0);
    const auto chosen = run_ode(s);
    EXPECT_EQ(setting(chosen.summary, "contact_surface_layer"), "0");
    Tuning layer;
    layer.surface_layer = 0.001;  // the samples' value
    const auto inert = run_ode(s, layer);
    ASSERT_EQ(inert.states.size(), chosen.states.size());
    for (std::size_t i = 0; i < chosen.states.size(); ++i) ASSERT_EQ(inert.states[i].p, chosen.states[i].p) << i;

    Tuning erp;
    erp.contact_soft_erp = false;
    erp.max_correcting_vel = std::numeric_limits<double>::infinity();
    const auto pushed = run_ode(s, erp);
    erp.surface_layer = 0.001;
    const auto layered = run_ode(s, erp);
    const double d_chosen = s.radius - chosen.states.back().p[1], d_pushed = s.radius - pushed.states.back().p[1],
                 d_layered = s.radius - layered.states.back().p[1];
    std::printf("final overlap with the floor: ERP 0 %.3e m, ERP 0.2 %.3e m, ERP 0.2 + layer 1 mm %.3e m\n", d_chosen,
                d_pushed, d_layered);
    EXPECT_GT(d_chosen, 0);
    EXPECT_LE(d_chosen, 0.0981 * s.dt * s.dt);  // at most the last step's fall under gravity
    EXPECT_LT(std::abs(d_pushed), 1e-12);
    EXPECT_GT(d_layered, 1e-6);
}

// Auto-disable: ODE's sleeping (when on: below 0.01 m/s and 0.01 rad/s for
// 10 steps, and only for a body with a joint, so never mid-air) freezes a slow
// ball touching a wall. ODE's default is off; the adapter sets it off on the
// world and the body. Here a ball sliding on the floor at 5 mm/s (mu = 0)
// stops dead after 10 steps with it on.
TEST(OdeTraps, AutoDisableOff) {
    Scenario s = with_per_contact(seed_at(3, 0.03, 3.0));
    s.position = {0.5, 0.5, s.radius};
    s.velocity = {0.005, 0.003, 0};
    const auto chosen = run_ode(s);
    EXPECT_EQ(setting(chosen.summary, "auto_disable"), "off");
    Tuning sleepy;
    sleepy.auto_disable = true;
    const auto trap = run_ode(s, sleepy);
    const double moved_chosen = chosen.states.back().p[0] - s.position[0];
    const double moved_trap = trap.states.back().p[0] - s.position[0];
    std::printf("sliding at 5 mm/s for %.2f s: moved %.3e m with auto-disable off, %.3e m with it on\n",
                chosen.states.back().t, moved_chosen, moved_trap);
    EXPECT_NEAR(moved_chosen, 0.005 * s.beta * chosen.states.back().t, 1e-12);
    EXPECT_LT(moved_trap, 0.2 * moved_chosen);
}

// mu: many samples use dInfinity, which makes every contact stick and roll at
// once (a free solid sphere keeps 5/7 of its tangential speed). With
// dContactApprox1 the friction impulse is mu x the normal impulse; without it
// mu is a force bound in newtons, so mu = 0.02 on a 1 kg ball hardly acts in
// one 1 ms step.
TEST(OdeTraps, FrictionIsCoulombWithMuFromTheOptions) {
    const Scenario s = friction_drop(0.02);
    const double mu = s.engine_options("ode").friction;
    const auto first = [&](const Tuning& t) {
        const auto run = run_ode(s, t);
        const auto c = floor_contacts(s, run.states).at(0);
        return std::pair{run.states[c.k - 1], run.states[c.k]};
    };
    const auto [before, after] = first(Tuning::chosen());
    // Sliding through the contact step: the normal impulse per unit mass is
    // (1 + alpha) v_n + g dt (it also holds the weight during the step).
    const double v_n = -before.v[1];
    const double expected_dv = mu * ((1 + s.alpha) * v_n + 0.0981 * s.dt);
    const double dv = before.v[0] - after.v[0];
    Tuning inf;
    inf.mu_override = std::numeric_limits<double>::infinity();
    const auto [b_inf, a_inf] = first(inf);
    Tuning approx0;
    approx0.approx1 = false;
    const auto [b_0, a_0] = first(approx0);
    std::printf("first floor contact, vx %.6f: dv mu 0.02 %.9e (Coulomb %.9e); ratio mu inf %.9f (5/7 = %.9f); "
                "dv Approx0 %.3e\n",
                before.v[0], dv, expected_dv, a_inf.v[0] / b_inf.v[0], 5.0 / 7.0, b_0.v[0] - a_0.v[0]);
    EXPECT_NEAR(dv, expected_dv, 1e-12);
    EXPECT_NEAR(a_inf.v[0] / b_inf.v[0], 5.0 / 7.0, 1e-9);
    EXPECT_LT(b_0.v[0] - a_0.v[0], 0.1 * expected_dv);
    const auto run = run_ode(s);
    EXPECT_EQ(setting(run.summary, "friction_mu").substr(0, 5), "0.02 ");
    EXPECT_NE(setting(run.summary, "friction_model").find("dContactApprox1"), std::string::npos);
}

// The pyramid: ODE bounds each of two friction rows by mu N. Along arbitrary
// axes a diagonal slip gets up to sqrt(2) mu N and turns; with the first row
// along the slip the friction is mu N against it, the direction kept.
TEST(OdeTraps, FrictionPyramidAlignedWithTheSlip) {
    Scenario s = seed_at(3, 1e-3, 7.0);
    s.position = {0.5, 0.5, 0.95};
    s.velocity = {0.04, 0.03, 0};  // diagonal, reaches no side wall before the floor
    EngineOptions opt;
    opt.friction = 0.01;
    s.engines["ode"] = opt;
    auto turn_and_loss = [&](const Tuning& t, double& loss) {
        const auto run = run_ode(s, t);
        const auto c = floor_contacts(s, run.states).at(0);
        const Vec3 a = run.states[c.k - 1].v, b = run.states[c.k].v;
        const double ta = std::atan2(a[1], a[0]), tb = std::atan2(b[1], b[0]);
        loss = std::hypot(a[0], a[1]) - std::hypot(b[0], b[1]);
        return tb - ta;
    };
    double loss_aligned = 0, loss_default = 0;
    const double turn_aligned = turn_and_loss(Tuning::chosen(), loss_aligned);
    Tuning def;
    def.align_friction = false;
    const double turn_default = turn_and_loss(def, loss_default);
    std::printf("diagonal slip: aligned turn %.3e rad loss %.6e; default axes turn %.3e rad loss %.6e\n",
                turn_aligned, loss_aligned, turn_default, loss_default);
    EXPECT_LT(std::abs(turn_aligned), 1e-9);
    EXPECT_GT(std::abs(turn_default), 1e-3);
}

// dWorldStep against dWorldQuickStep: QuickStep's SOR iterations only
// approach the LCP's solution (by ~6e-11 here: small, but not the law);
// dWorldStep's Dantzig solve gives restitution alpha to round-off.
TEST(OdeTraps, WorldStepSolvesTheBounceExactly) {
    const Scenario s = friction_drop(0.02);
    const auto chosen = run_ode(s);
    EXPECT_EQ(setting(chosen.summary, "stepper"), "dWorldStep");
    Tuning quick;
    quick.stepper = ode::Stepper::quick_step;
    const auto trap = run_ode(s, quick);
    const double e_chosen = floor_contacts(s, chosen.states).at(0).restitution();
    const double e_quick = floor_contacts(s, trap.states).at(0).restitution();
    std::printf("restitution, friction 0.02: dWorldStep %.15f, dWorldQuickStep(20) %.15f\n", e_chosen, e_quick);
    EXPECT_NEAR(e_chosen, s.alpha, 1e-14);
    EXPECT_GT(std::abs(e_quick - s.alpha), 1e-13);
}

// WallContact points: sphere against plane gives one point per wall, so each wall
// contact is one constraint row (several points would share one impulse and
// could turn the ball). A corner gives one contact per wall, each bouncing by
// alpha along its own axis.
TEST(OdeTraps, OneContactPointPerWallAndCornersBounceOnBothAxes) {
    Scenario s = seed_at(2, 1e-3, 3.0);
    s.gravity = {0, 0, 0};
    s.position = {0.5, 0.5, 0};
    s.velocity = {0.3, 0.3, 0};  // reaches the upper-right corner: both walls at once
    std::vector<Setting> settings;
    const auto world = ode::build_world(s, s.engine_options("ode"), Tuning::chosen(), settings);
    State prev{0, s.position, s.velocity}, cur;
    bool corner = false;
    for (int i = 0; i < 3000; ++i) {
        world->step();
        world->read(cur);
        if (prev.v[0] > 0 && cur.v[0] <= 0) {
            EXPECT_NEAR(-cur.v[0] / prev.v[0], s.alpha, 1e-12);
            EXPECT_NEAR(-cur.v[1] / prev.v[1], s.alpha, 1e-12);  // the same step: a corner
            corner = true;
        }
        prev = cur;
    }
    EXPECT_TRUE(corner);
    EXPECT_EQ(world->stats().max_contacts_per_pair, 1);
    EXPECT_GE(world->stats().pairs_touching, 2);
}

// per_contact: mu = 0 and the near callback scales the components along the
// wall by beta once per contact: a bounce gives exactly beta, and a ball
// sliding on the floor (contact lasting every step) is scaled only once.
// seed-2d's ball starts at rest against the ceiling, gravity pulling it away:
// not a contact for the law (see moves_into_wall).
TEST(OdePerContact, StartingAtRestAgainstTheCeilingIsNotAContact) {
    const Scenario s = with_per_contact(seed_at(2, 0.03, 0.3));
    const auto run = run_ode(s);
    EXPECT_EQ(run.states.back().v[0], 0.3);
}

TEST(OdePerContact, BetaOncePerContact) {
    Scenario s = seed_at(2, 1e-3, 5.0);
    EngineOptions opt;
    opt.tangential_model = TangentialModel::per_contact;
    s.engines["ode"] = opt;
    const auto run = run_ode(s);
    EXPECT_EQ(setting(run.summary, "friction_mu").substr(0, 2), "0 ");
    const auto c = floor_contacts(s, run.states).at(0);
    EXPECT_NEAR(run.states[c.k].v[0] / run.states[c.k - 1].v[0], s.beta, 1e-12);

    Scenario slide = seed_at(2, 1e-3, 1.0);
    slide.engines["ode"] = opt;
    slide.position = {0.2, slide.radius, 0};
    slide.velocity = {0.3, 0, 0};  // resting on the floor, sliding for 1000 steps
    std::vector<Setting> settings;
    const auto world = ode::build_world(slide, opt, Tuning::chosen(), settings);
    for (int i = 0; i < 1000; ++i) world->step();
    State st;
    world->read(st);
    std::printf("sliding 1000 steps in contact: vx %.15f (0.3 beta = %.15f), new contacts %lld\n", st.v[0],
                0.3 * s.beta, static_cast<long long>(world->stats().new_contacts));
    EXPECT_NEAR(st.v[0], 0.3 * s.beta, 1e-12);
    EXPECT_EQ(world->stats().new_contacts, 1);
    EXPECT_EQ(world->stats().pairs_touching, 1000);
}

// Rotation lock: with free_rotation = false friction cannot spin the ball.
TEST(OdeRotation, LockedRotationStaysZero) {
    Scenario s = seed_at(3, 0.03, 42.0);
    EngineOptions opt;
    opt.friction = 0.05;
    opt.free_rotation = false;
    s.engines["ode"] = opt;
    std::vector<Setting> settings;
    const auto world = ode::build_world(s, opt, Tuning::chosen(), settings);
    double max_w = 0;
    for (int i = 0; i < 1400; ++i) {
        world->step();
        max_w = std::max(max_w, world->engine_angular_velocity().norm());
    }
    EXPECT_LT(max_w, 1e-12);
}

// Global init: repeated runs and several live worlds give identical results.
TEST(OdeInit, RepeatedRunsAndSeveralWorldsAgree) {
    const Scenario s = seed(3);
    std::vector<Setting> settings;
    const auto a = ode::build_world(s, {}, Tuning::chosen(), settings);
    const auto b = ode::build_world(s, {}, Tuning::chosen(), settings);
    State sa, sb;
    for (int i = 0; i < 1400; ++i) {
        a->step();
        b->step();
    }
    a->read(sa);
    b->read(sb);
    EXPECT_EQ(sa.p, sb.p);
    EXPECT_EQ(sa.v, sb.v);
    const auto r1 = test::run_simulator("ode", s), r2 = test::run_simulator("ode", s);
    EXPECT_EQ(r1.summary.final_state.p, r2.summary.final_state.p);
    EXPECT_EQ(r1.summary.final_state.p, sa.p);
}

}  // namespace
}  // namespace bouncecheck

namespace bouncecheck {
namespace {

class OdeCalibrateCli : public test::TestDirectory {};

// `calibrate --against exact` fits mu to the law's solution, not the
// document's Euler: another objective, so another mu, and the file says which.
TEST_F(OdeCalibrateCli, AgainstExactFitsAnotherMuAndSaysSo) {
    const std::string seed = std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-2d.toml";
    const auto vs_reference = test::bouncecheck("calibrate " + seed + " --engine ode");
    ASSERT_EQ(vs_reference.status, 0) << vs_reference.output;
    EXPECT_NE(vs_reference.output.find("from reference over the run"), std::string::npos) << vs_reference.output;

    const std::filesystem::path copy = write_file("seed-2d.toml", test::slurp(seed));
    const auto vs_exact = test::bouncecheck("calibrate " + copy.string() + " --engine ode --against exact --write");
    ASSERT_EQ(vs_exact.status, 0) << vs_exact.output;
    EXPECT_NE(vs_exact.output.find("from exact over the run"), std::string::npos) << vs_exact.output;
    const Scenario written = load_scenario(copy.string());
    const double mu_exact = written.engine_options("ode").friction;
    EXPECT_NE(test::slurp(copy).find("m from exact"), std::string::npos);
    const auto mu_in = [](const std::string& output) {
        const auto at = output.find("mu = ");
        return at == std::string::npos ? -1.0 : std::stod(output.substr(at + 5));
    };
    EXPECT_NEAR(mu_in(vs_exact.output), mu_exact, 1e-5 * mu_exact);
    EXPECT_GT(std::abs(mu_exact - mu_in(vs_reference.output)), 0.1 * mu_exact) << vs_reference.output;

    const auto unknown = test::bouncecheck("calibrate " + seed + " --engine ode --against truth");
    EXPECT_EQ(unknown.status, 2) << unknown.output;
    EXPECT_NE(unknown.output.find("truth not in {reference,exact}"), std::string::npos) << unknown.output;
}

}  // namespace
}  // namespace bouncecheck
