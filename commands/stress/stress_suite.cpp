#include "commands/stress/stress_suite.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string_view>
#include <utility>

namespace bouncecheck {

double unit_draw(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1p-53; }

namespace {

double uniform(std::mt19937_64& g, double lo, double hi) { return lo + (hi - lo) * unit_draw(g); }
// One of n outcomes; the modulo bias (n / 2^64) is far below anything measurable.
std::uint64_t pick(std::mt19937_64& g, std::uint64_t n) { return g() % n; }
bool one_in(std::mt19937_64& g, std::uint64_t n) { return pick(g, n) == 0; }

}  // namespace

std::vector<Scenario> monte_carlo_scenarios(std::uint64_t seed, int count,
                                            const std::function<bool(const std::string& name)>& keep) {
    std::mt19937_64 g(seed);
    std::vector<Scenario> out;
    if (!keep) out.reserve(static_cast<std::size_t>(std::max(0, count)));
    Scenario s;  // reused: a scenario not kept costs its draws only
    for (int n = 0; n < count; ++n) {
        s.name = fmt::format("{}-{:04d}", kMonteCarloRow, n);
        s.dim = 2 + static_cast<int>(pick(g, 2));
        s.room = s.position = s.velocity = s.gravity = Vec3::Zero();
        for (int i = 0; i < s.dim; ++i) s.room[i] = uniform(g, 0.2, 3.0);
        s.radius = s.room.head(s.dim).minCoeff() * uniform(g, 0.005, 0.2);
        const double r = s.radius;
        const bool no_gravity = one_in(g, 10);
        for (int i = 0; i < s.dim; ++i) {
            const double high = s.room[i] - r;
            // A start touching a wall, one axis in eight; the clamp keeps a
            // rounded r + (high - r) u within [r, high], as the loader requires.
            switch (pick(g, 16)) {
                case 0: s.position[i] = r; break;
                case 1: s.position[i] = high; break;
                default: s.position[i] = std::min(high, std::max(r, uniform(g, r, high)));
            }
            s.velocity[i] = one_in(g, 8) ? 0.0 : uniform(g, -2.0, 2.0);
            const bool vertical = i == s.dim - 1;
            if (!no_gravity) s.gravity[i] = vertical ? -uniform(g, 0.0, 10.0) : (one_in(g, 4) ? uniform(g, -1.0, 1.0) : 0.0);
        }
        auto factor = [&](double lo) {
            switch (pick(g, 8)) {
                case 0: return 0.0;
                case 1: return 1.0;
                default: return uniform(g, lo, 1.0);
            }
        };
        s.alpha = factor(0.0);
        s.beta = factor(0.5);
        // dt = m 2^-e, m in [1, 2): log-uniform-like without a libm call.
        s.dt = std::ldexp(uniform(g, 1.0, 2.0), -static_cast<int>(5 + pick(g, 8)));
        s.duration = s.dt * static_cast<double>(200 + pick(g, 1801));
        if (keep && !keep(s.name)) continue;
        s.description = fmt::format("Monte-Carlo scenario {} of seed {}", n, seed);
        out.push_back(s);
    }
    return out;
}

std::vector<Scenario> wall_start_scenarios() {
    static constexpr std::array<const char*, 3> kAxis{"x", "y", "z"};
    std::vector<Scenario> out;
    for (const int dim : {2, 3}) {
        for (int axis = 0; axis < dim; ++axis) {
            for (const int side : {-1, +1}) {
                for (const char* motion : {"in", "out", "rest"}) {
                    Scenario s;
                    s.dim = dim;
                    s.room = s.velocity = s.gravity = Vec3::Zero();
                    s.position = Vec3::Zero();
                    for (int i = 0; i < dim; ++i) {
                        s.room[i] = 1.0;
                        s.position[i] = 0.5;
                    }
                    s.radius = 0.05;
                    s.gravity[dim - 1] = -0.0981;
                    s.position[axis] = side < 0 ? s.radius : 1.0 - s.radius;
                    const double into = std::string_view(motion) == "in" ? 0.3 : std::string_view(motion) == "out" ? -0.3 : 0.0;
                    s.velocity[axis] = side * into;
                    // Some motion along the wall too, so that beta has something to damp.
                    if (into != 0.0) s.velocity[(axis + 1) % dim] = 0.1;
                    s.alpha = 0.8;
                    s.beta = 0.99;
                    s.dt = 0.03;
                    s.duration = 10.0;
                    s.name = fmt::format("wall-start-{}d-{}-{}-{}", dim, kAxis[static_cast<std::size_t>(axis)],
                                         side < 0 ? "lower" : "upper", motion);
                    s.description = fmt::format("starts touching the {} {} wall, {}", side < 0 ? "lower" : "upper",
                                                kAxis[static_cast<std::size_t>(axis)],
                                                into > 0 ? "moving into it" : into < 0 ? "moving away" : "at rest");
                    out.push_back(std::move(s));
                }
            }
        }
    }
    return out;
}

std::vector<StressCase> stress_suite(const std::vector<Scenario>& files, const MonteCarloSet& monte_carlo,
                                     const StressCaseFilter& keep) {
    const auto kept = [&](const char* row, const std::string& name) { return !keep || keep(row, name); };
    std::vector<Scenario> generated = monte_carlo_scenarios(
        monte_carlo.seed, monte_carlo.count, keep ? [&](const std::string& name) { return keep(kMonteCarloRow, name); }
                                                  : std::function<bool(const std::string&)>{});
    std::vector<StressCase> cases;
    for (const Scenario& s : files)
        if (kept(s.name.c_str(), s.name)) cases.push_back({s.name, s, false});
    for (Scenario& s : wall_start_scenarios())
        if (kept(kWallStartsRow, s.name)) cases.push_back({kWallStartsRow, std::move(s), true});
    cases.reserve(cases.size() + generated.size());
    for (Scenario& s : generated) cases.push_back({kMonteCarloRow, std::move(s), true});
    return cases;
}

}  // namespace bouncecheck
