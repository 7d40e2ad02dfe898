// Cost of the reference step and of the exact solve, on the real code paths.
//
//   taskset -c 1 build/bench/bench_reference --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// Targets and measured numbers: bench/README.md.
//
// ReferenceStep/N: seed-3d run to its end over N steps (N = 1e3 ... 1e8) by
// ReferenceModel::run_to_end(), the model's own loop (free flight between
// contacts, the periodic rest skipped); the per-step cost must stay flat as
// the run enters the Zeno regime. ReferenceStepByStep/N: the same run one
// step() at a time with state() read after each, as a streaming consumer
// does. NaiveStep/N is the same model with plain hardware arithmetic (no
// subnormal handling), for the side-by-side ratio; NaiveStepElastic/N the
// same on the elastic seed. ReferenceRun/N: the whole
// `reference` simulator (Simulator::run with the metrics recorder), as
// `bouncecheck run` runs it.
#include "exact/exact_model.h"
#include "metrics/summary.h"
#include "reference/plain_reference_model.h"
#include "reference/reference_model.h"
#include "reference/reference_simulator.h"
#include "simulators/simulator.h"

#include <benchmark/benchmark.h>

#include <cstdint>

namespace {

using namespace bouncecheck;

Scenario seed3d_with_steps(std::int64_t steps) {
    Scenario s;  // the defaults are seed-3d
    s.duration = s.dt * static_cast<double>(steps);
    return s;
}

void set_per_step(benchmark::State& state, std::int64_t steps) {
    state.counters["ns_per_step"] =
        benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void ReferenceStep(benchmark::State& state) {
    const Scenario s = seed3d_with_steps(state.range(0));
    std::int64_t steps = 0, repeat_at = 0;
    for (auto _ : state) {
        ReferenceModel<3> model(s);
        model.run_to_end();
        steps += model.steps();
        repeat_at = model.repeat_found_at();
        benchmark::DoNotOptimize(model.state());
    }
    set_per_step(state, steps);
    state.counters["repeat_found_at"] = static_cast<double>(repeat_at);
}

void ReferenceStepByStep(benchmark::State& state) {
    const Scenario s = seed3d_with_steps(state.range(0));
    std::int64_t steps = 0;
    for (auto _ : state) {
        ReferenceModel<3> model(s);
        while (model.running()) {
            benchmark::DoNotOptimize(model.step());
            benchmark::DoNotOptimize(model.state());
        }
        steps += model.steps();
    }
    set_per_step(state, steps);
}

// The document's model written plainly (no subnormal handling), stepped
// over `s`'s clock.
void plain_loop(benchmark::State& state, const Scenario& s) {
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
    set_per_step(state, steps);
}

void NaiveStep(benchmark::State& state) { plain_loop(state, seed3d_with_steps(state.range(0))); }

// The same plain loop on the elastic seed (alpha = beta = 1): no velocity
// decays into the subnormals, so every step runs at hardware speed. The
// yardstick of a long run's cost (bench/README.md, 7).
void NaiveStepElastic(benchmark::State& state) {
    Scenario s = seed3d_with_steps(state.range(0));
    s.alpha = s.beta = 1;
    plain_loop(state, s);
}

void ReferenceRun(benchmark::State& state) {
    const Scenario s = seed3d_with_steps(state.range(0));
    const auto sim = make_reference_simulator();
    std::int64_t steps = 0;
    for (auto _ : state) {
        const SimulatorSummary summary = record_run(*sim, s);
        steps += summary.steps;
        benchmark::DoNotOptimize(summary.final_state);
    }
    set_per_step(state, steps);
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
BENCHMARK(ReferenceStepByStep)->Arg(1000)->Arg(100000)->Arg(10000000)->Unit(benchmark::kMillisecond);
BENCHMARK(NaiveStep)->Arg(1000)->Arg(1400)->Arg(100000)->Arg(10000000)->Arg(100000000)->Unit(benchmark::kMillisecond);
BENCHMARK(NaiveStepElastic)->Arg(100000000)->Unit(benchmark::kMillisecond);
BENCHMARK(ReferenceRun)->Arg(1000)->Arg(100000)->Arg(10000000)->Arg(100000000)->Unit(benchmark::kMillisecond);
BENCHMARK(ExactSolve)->Arg(42)->Arg(1000)->Arg(100000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
