// The reference is explicit Euler on the same damping law as exact, so its
// trajectory error against exact must fall at first order as dt halves.
#include "exact/exact_model.h"
#include "reference/reference_model.h"
#include "scenarios/loader.h"
#include "support/convergence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace bouncecheck {
namespace {

// RMS distance between the reference's centre and the exact centre at the
// reference's sample times, over [0, horizon].
template <int D>
double trajectory_rms(const Scenario& s, const ExactModel& exact, double horizon) {
    ReferenceModel<D> model(s);
    double sum = 0;
    long n = 0;
    while (model.running()) {
        model.step();
        const State st = model.state();
        if (st.t > horizon) break;
        sum += (st.p - exact.state_at(st.t).p).squaredNorm();
        ++n;
    }
    return std::sqrt(sum / static_cast<double>(n));
}

void expect_first_order(const std::string& file) {
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + file);
    const ExactModel exact(s);
    // Compare before the Zeno accumulation: there every simulator with a
    // finite step parts from the exact solution's infinitely many bounces.
    const double horizon = exact.rest_time() ? 0.8 * *exact.rest_time() : s.duration;
    std::vector<double> dts, errors;
    const double seed_dt = s.dt;
    for (double dt = seed_dt; dt > seed_dt / 300; dt /= 2) {
        s.dt = dt;
        const double e = s.dim == 2 ? trajectory_rms<2>(s, exact, horizon) : trajectory_rms<3>(s, exact, horizon);
        dts.push_back(dt);
        errors.push_back(e);
        ::testing::Test::RecordProperty("rms_dt_" + std::to_string(dt), std::to_string(e));
    }
    const double order = test::fitted_order(dts, errors);
    ::testing::Test::RecordProperty("order", std::to_string(order));
    std::printf("%s: fitted order %.3f over dt %.3g .. %.3g (rms %.3g .. %.3g m)\n", file.c_str(), order, dts.front(),
                dts.back(), errors.front(), errors.back());
    EXPECT_NEAR(order, 1.0, 0.1);
}

TEST(Convergence, ReferenceConvergesToExactAtFirstOrder3d) { expect_first_order("seed-3d.toml"); }
TEST(Convergence, ReferenceConvergesToExactAtFirstOrder2d) { expect_first_order("seed-2d.toml"); }

}  // namespace
}  // namespace bouncecheck
