// Cost of the reference step and of the exact solve, on the real code paths.
//
//   build/bench/bench_reference --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// ReferenceStep/N runs seed-3d for N steps (N = 1e3 ... 1e8): the per-step
// cost must stay flat as the run enters the Zeno regime, where tangential
// velocities become subnormal. NaiveStep/N is the same model with plain
// hardware arithmetic, for the side-by-side ratio.
#include "reference/exact_model.h"
#include "reference/reference_model.h"

#include <benchmark/benchmark.h>

#include <array>

namespace {

using namespace bouncecheck;

Scenario seed3d_with_steps(std::int64_t steps) {
    Scenario s;  // the defaults are seed-3d
    s.duration = s.dt * static_cast<double>(steps);
    return s;
}

void ReferenceStep(benchmark::State& state) {
    const Scenario s = seed3d_with_steps(state.range(0));
    std::int64_t steps = 0;
    for (auto _ : state) {
        ReferenceModel<3> model(s);
        while (model.running()) {
            benchmark::DoNotOptimize(model.step());
            ++steps;
        }
        benchmark::DoNotOptimize(model.state());
    }
    state.counters["ns_per_step"] =
        benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// The document's model written plainly: no subnormal handling.
void NaiveStep(benchmark::State& state) {
    const Scenario s = seed3d_with_steps(state.range(0));
    std::int64_t steps = 0;
    for (auto _ : state) {
        std::array<double, 3> p{s.position[0], s.position[1], s.position[2]};
        std::array<double, 3> v{s.velocity[0], s.velocity[1], s.velocity[2]};
        const double r = s.radius, a = s.alpha, f = (s.alpha + s.beta) - s.alpha;
        for (double t = 0; std::abs(t) < std::abs(s.duration); t = t + s.dt) {
            unsigned lo = 0, up = 0;
            for (int i = 0; i < 3; ++i) {
                const double moved = p[i] + v[i] * s.dt;
                double q = (moved - r > 0.0) ? moved : r;
                if (!(moved + r < s.room[i])) q = s.room[i] - r;
                p[i] = q + 0.0;
            }
            for (int i = 0; i < 3; ++i) {
                v[i] = v[i] + s.gravity[i] * s.dt;
                if (!(p[i] - r > 0.0)) lo |= 1u << i;
                if (!(p[i] + r < s.room[i])) up |= 1u << i;
            }
            for (unsigned mask : {lo, up})
                if (mask)
                    for (int i = 0; i < 3; ++i) v[i] = v[i] * (((mask >> i) & 1u) ? -a : f) + 0.0;
            ++steps;
        }
        benchmark::DoNotOptimize(p);
        benchmark::DoNotOptimize(v);
    }
    state.counters["ns_per_step"] =
        benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// The whole exact solution of seed-3d (contacts and Zeno tail), without sampling.
void ExactSolve(benchmark::State& state) {
    Scenario s;
    s.duration = static_cast<double>(state.range(0));
    for (auto _ : state) {
        ExactModel model(s);
        benchmark::DoNotOptimize(model.contacts().data());
    }
}

BENCHMARK(ReferenceStep)->Arg(1000)->Arg(1400)->Arg(100000)->Arg(10000000)->Arg(100000000)->Unit(benchmark::kMillisecond);
BENCHMARK(NaiveStep)->Arg(1000)->Arg(1400)->Arg(100000)->Arg(10000000)->Arg(100000000)->Unit(benchmark::kMillisecond);
BENCHMARK(ExactSolve)->Arg(42)->Arg(1000)->Arg(100000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
