// What hosting an engine in Node adds to its own step (docs/engines.md, the
// Node-hosted engines): each engine on the seed of each of its dimensions in
// per-contact mode at dt = 1e-3, through the harness exactly as `sweep` and
// `stress` run it (a session reused run after run: Node's start-up and the
// engine's load are paid before the timing starts). Per run, per step:
// - engine_ns: the engine's own step, as the adapter times it (the #end
//   line's step_seconds over the steps);
// - harness_ns: what every simulator costs the harness per step, compiled or
//   hosted: the reference on the same scenario through the same recorder
//   (contact detection, metrics), its own Euler step included (a few ns);
// - overhead_pct: what the adapter and the protocol add, as a share of the
//   engine's step: the run's wall time less the engine's steps and the
//   harness's share (the adapter's reads of the state, the rows, the pipe,
//   the timing of each step, the reading of the rows);
// - outside_pct: everything outside the engine's step, the harness included.
//
//   build/bench/bench_node_engines --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include "registry/node_engines.h"
#include "metrics/summary.h"
#include "registry/registry.h"
#include "scenarios/loader.h"

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <string>

namespace {

using namespace bouncecheck;

Scenario seed_per_contact(int dim, const std::string& engine) {
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + (dim == 3 ? "/seed-3d.toml" : "/seed-2d.toml"));
    s.dt = 1e-3;
    EngineOptions options;
    options.tangential_model = TangentialModel::per_contact;
    s.engines[engine] = options;
    return s;
}

void HostedEngineRun(benchmark::State& state, const std::string& engine, int dim) {
    const auto all = built_simulators();
    const Simulator* sim = nullptr;
    const Simulator* reference = nullptr;
    for (const auto& candidate : all) {
        if (candidate->name() == engine) sim = candidate.get();
        if (candidate->name() == "reference") reference = candidate.get();
    }
    const Scenario s = seed_per_contact(dim, engine);
    if (!sim || !reference || sim->cannot_run(s)) return state.SkipWithError("cannot run");
    if (record_run(*sim, s).status != RunStatus::ok) return state.SkipWithError("failed");  // the session's start-up
    double wall = 0, step = 0, harness = 0;
    std::int64_t steps = 0;
    for (auto _ : state) {
        const SimulatorSummary r = record_run(*sim, s);
        if (r.status != RunStatus::ok || !r.step_seconds) return state.SkipWithError(r.reason.c_str());
        wall += r.run_seconds;
        step += *r.step_seconds;
        steps += r.steps;
        state.PauseTiming();
        harness += record_run(*reference, s).run_seconds;
        state.ResumeTiming();
    }
    const double per_step = 1e9 / static_cast<double>(steps);
    state.counters["engine_ns"] = step * per_step;
    state.counters["harness_ns"] = harness * per_step;
    state.counters["overhead_pct"] = 100 * (wall - step - harness) / step;
    state.counters["outside_pct"] = 100 * (wall - step) / step;
}

}  // namespace

int main(int argc, char** argv) {
    for (const bouncecheck::NodeEngine& engine : bouncecheck::node_engines())
        for (const int dim : {3, 2})
            if (dim == 3 ? engine.runs_3d : engine.runs_2d)
                benchmark::RegisterBenchmark(fmt::format("NodeEngine/{}_{}d", engine.name, dim).c_str(), HostedEngineRun,
                                             std::string(engine.name), dim)
                    ->Unit(benchmark::kMillisecond)
                    ->UseRealTime()
                    ->Iterations(3);
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
