// What the shared engine loop costs on top of the engine: each engine run
// through its adapter's Simulator::run (EngineSimulator::run: clock, read
// back, stream contact detection and the metrics recorder) against a bare
// loop calling the same world's step() for the same number of steps, the
// world built by the adapter's own build_world with the same tuning. Both
// include building the world. Bullet and ODE run seed-3d, Box2D seed-2d
// (it is a 2D engine).
//
//   taskset -c 1 build/bench/bench_engines --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// Target: EngineRun within 5% of EngineBare per engine (bench/README.md).
#include "adapters/engine.h"
#include "reference/document_clock.h"
#include "scenarios/loader.h"

#ifdef BOUNCECHECK_WITH_BULLET
#include "adapters/bullet/bullet_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_ODE
#include "adapters/ode/ode_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_BOX2D
#include "adapters/box2d/box2d_adapter.h"
#endif

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace bouncecheck;

Scenario bundled(const std::string& file) {
    return load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + file);
}

using BuildWorld = std::function<std::unique_ptr<EngineWorld>(const Scenario&, const EngineOptions&,
                                                              std::vector<SimulatorSummary::Setting>&)>;

// The engine's own steps and nothing else: no clock, no read-back, no recording.
void bare(benchmark::State& state, const Scenario& s, const std::string& engine, const BuildWorld& build) {
    const EngineOptions options = s.engine_options(engine);
    const std::int64_t steps = document_step_count(s.dt, s.duration);
    // The same substeps as the shared loop: a world built for dt / substeps.
    const int substeps = std::max(1, options.substeps);
    Scenario engine_scenario = s;
    engine_scenario.dt = s.dt / substeps;
    for (auto _ : state) {
        std::vector<SimulatorSummary::Setting> settings;
        const std::unique_ptr<EngineWorld> world = build(engine_scenario, options, settings);
        for (std::int64_t n = 0; n < steps * substeps; ++n) world->step();
        State last;
        world->read(last);
        benchmark::DoNotOptimize(last);
    }
    state.counters["per_step"] = benchmark::Counter(static_cast<double>(steps * state.iterations()),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// The adapter's real path with metrics streamed (no trajectory sink).
void adapter(benchmark::State& state, const Scenario& s, const Simulator& sim) {
    std::int64_t steps = 0;
    for (auto _ : state) {
        const SimulatorSummary summary = sim.run(s, nullptr);
        if (summary.status != RunStatus::ok) state.SkipWithError(summary.reason.c_str());
        steps += summary.steps;
        benchmark::DoNotOptimize(summary.final_state);
    }
    state.counters["per_step"] = benchmark::Counter(static_cast<double>(steps),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

#ifdef BOUNCECHECK_WITH_BULLET
void EngineBare_bullet(benchmark::State& state) {
    bare(state, bundled("seed-3d.toml"), "bullet", [](const Scenario& s, const EngineOptions& o, auto& settings) {
        return std::unique_ptr<EngineWorld>(bullet::build_world(s, o, bullet::Tuning::chosen(), settings));
    });
}
void EngineRun_bullet(benchmark::State& state) {
    adapter(state, bundled("seed-3d.toml"), *bullet::make_simulator(bullet::Tuning::chosen()));
}
BENCHMARK(EngineBare_bullet)->Unit(benchmark::kMillisecond);
BENCHMARK(EngineRun_bullet)->Unit(benchmark::kMillisecond);
#endif

#ifdef BOUNCECHECK_WITH_ODE
void EngineBare_ode(benchmark::State& state) {
    bare(state, bundled("seed-3d.toml"), "ode", [](const Scenario& s, const EngineOptions& o, auto& settings) {
        return std::unique_ptr<EngineWorld>(ode::build_world(s, o, ode::Tuning::chosen(), settings));
    });
}
void EngineRun_ode(benchmark::State& state) {
    adapter(state, bundled("seed-3d.toml"), *ode::make_simulator(ode::Tuning::chosen()));
}
BENCHMARK(EngineBare_ode)->Unit(benchmark::kMillisecond);
BENCHMARK(EngineRun_ode)->Unit(benchmark::kMillisecond);
#endif

#ifdef BOUNCECHECK_WITH_BOX2D
void EngineBare_box2d(benchmark::State& state) {
    bare(state, bundled("seed-2d.toml"), "box2d", [](const Scenario& s, const EngineOptions& o, auto& settings) {
        return box2d::build_world(s, o, box2d::Tuning{}, settings);
    });
}
void EngineRun_box2d(benchmark::State& state) {
    adapter(state, bundled("seed-2d.toml"), *box2d::make_simulator(box2d::Tuning{}));
}
BENCHMARK(EngineBare_box2d)->Unit(benchmark::kMillisecond);
BENCHMARK(EngineRun_box2d)->Unit(benchmark::kMillisecond);
#endif

}  // namespace

BENCHMARK_MAIN();
