// What the shared engine loop costs on top of the engine: each engine run
// through its adapter's Simulator::run (EngineSimulator::run: clock, read
// back, stream contact detection and the metrics recorder) against a bare
// loop calling the same world's step() for the same number of steps, the
// world built as run() builds it (build_stepped_world). Both
// include building the world. Bullet and ODE run seed-3d, Box2D seed-2d
// (it is a 2D engine).
//
//   taskset -c 1 build/bench/bench_engines --benchmark_filter=Paired --benchmark_min_time=5
//
// Target: EngineRun within 5% of EngineBare per engine; EnginePaired_<engine>
// measures it side by side as `overhead_pct` (bench/README.md).
#include "bench/paired_timing.h"
#include "engines/engine.h"
#include "metrics/summary.h"
#include "scenarios/loader.h"
#include "simulators/document_clock.h"

#ifdef BOUNCECHECK_WITH_BULLET
#include "engines/bullet/bullet_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_ODE
#include "engines/ode/ode_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_BOX2D
#include "engines/box2d/box2d_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_MUJOCO
#include "engines/mujoco/mujoco_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_CHIPMUNK
#include "engines/chipmunk/chipmunk_adapter.h"
#endif

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace bouncecheck;

Scenario bundled(const std::string& file) {
    return load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + file);
}

// The engine's own steps and nothing else: no clock, no read-back, no
// recording. The world is the one the adapter's run() steps, built the same
// way (EngineSimulator::build_stepped_world, substeps included).
State run_bare(const Scenario& s, const EngineSimulator& sim, std::int64_t steps) {
    std::vector<Setting> settings;
    const EngineSimulator::SteppedWorld built = sim.build_stepped_world(s, settings);
    for (std::int64_t n = 0; n < steps * built.substeps; ++n) built.world->step();
    State last;
    built.world->read(last);
    return last;
}

void bare(benchmark::State& state, const Scenario& s, const EngineSimulator& sim) {
    const std::int64_t steps = document_step_count(s.dt, s.duration);
    for (auto _ : state) benchmark::DoNotOptimize(run_bare(s, sim, steps));
    state.counters["per_step"] = benchmark::Counter(static_cast<double>(steps * state.iterations()),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// The adapter's real path with metrics streamed (no trajectory sink).
void adapter(benchmark::State& state, const Scenario& s, const Simulator& sim) {
    std::int64_t steps = 0;
    for (auto _ : state) {
        const SimulatorSummary summary = record_run(sim, s);
        if (summary.status != RunStatus::ok) state.SkipWithError(summary.reason.c_str());
        steps += summary.steps;
        benchmark::DoNotOptimize(summary.final_state);
    }
    state.counters["per_step"] = benchmark::Counter(static_cast<double>(steps),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Both side by side (bench/paired_timing.h): `overhead_pct` is the median
// over the iterations of 100 (adapter / bare - 1).
void paired(benchmark::State& state, const Scenario& s, const EngineSimulator& sim) {
    const std::int64_t steps = document_step_count(s.dt, s.duration);
    const bench::PairedSeconds t = bench::time_pairs(
        state, [&] { benchmark::DoNotOptimize(run_bare(s, sim, steps)); },
        [&] {
            const SimulatorSummary summary = record_run(sim, s);
            if (summary.status != RunStatus::ok) state.SkipWithError(summary.reason.c_str());
            benchmark::DoNotOptimize(summary.final_state);
        });
    std::vector<double> ratios;
    for (std::size_t i = 0; i < t.first.size(); ++i) ratios.push_back(t.second[i] / t.first[i]);
    state.counters["overhead_pct"] = 100 * (bench::median(ratios) - 1);
    state.counters["pairs"] = static_cast<double>(ratios.size());
}

// One row per built engine: its scenario and its adapter as `run` uses it.
struct EngineCase {
    std::string engine, scenario;
    std::unique_ptr<const Simulator> simulator;
};

std::vector<EngineCase> engine_cases() {
    std::vector<EngineCase> cases;
#ifdef BOUNCECHECK_WITH_BULLET
    cases.push_back({"bullet", "seed-3d.toml", bullet::make_simulator(bullet::Tuning::chosen())});
#endif
#ifdef BOUNCECHECK_WITH_ODE
    cases.push_back({"ode", "seed-3d.toml", ode::make_simulator(ode::Tuning::chosen())});
#endif
#ifdef BOUNCECHECK_WITH_BOX2D
    cases.push_back({"box2d", "seed-2d.toml", box2d::make_simulator(box2d::Tuning{})});
#endif
#ifdef BOUNCECHECK_WITH_MUJOCO
    cases.push_back({"mujoco", "seed-3d.toml", mujoco::make_simulator(mujoco::Tuning::chosen())});
#endif
#ifdef BOUNCECHECK_WITH_CHIPMUNK
    cases.push_back({"chipmunk", "seed-2d.toml", chipmunk::make_simulator(chipmunk::Tuning{})});
#endif
    return cases;
}

}  // namespace

int main(int argc, char** argv) {
    static const std::vector<EngineCase> cases = engine_cases();
    for (const EngineCase& c : cases) {
        const Scenario s = bundled(c.scenario);
        const auto& sim = dynamic_cast<const EngineSimulator&>(*c.simulator);
        benchmark::RegisterBenchmark(("EngineBare_" + c.engine).c_str(),
                                     [&sim, s](benchmark::State& st) { bare(st, s, sim); })
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("EngineRun_" + c.engine).c_str(),
                                     [&sim, s](benchmark::State& st) { adapter(st, s, sim); })
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("EnginePaired_" + c.engine).c_str(),
                                     [&sim, s](benchmark::State& st) { paired(st, s, sim); })
            ->Unit(benchmark::kMillisecond);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
