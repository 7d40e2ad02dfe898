// Cost of the reference step and of the exact solve, on the real code paths.
//
//   build/bench/bench_reference --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// ReferenceStep/N runs seed-3d for N steps (N = 1e3 ... 1e8): the per-step
// cost must stay flat as the run enters the Zeno regime, where tangential
// velocities become subnormal. NaiveStep/N is the same model with plain
// hardware arithmetic, for the side-by-side ratio.
#include "reference/exact_model.h"
#include "reference/plain_reference_model.h"
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
        PlainReferenceModel3d model(s);
        for (DocumentClock clock(s.dt, s.duration); clock.running(); clock.advance()) {
            model.step();
            ++steps;
        }
        benchmark::DoNotOptimize(model.p);
        benchmark::DoNotOptimize(model.v);
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
