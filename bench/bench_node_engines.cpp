// What hosting an engine in Node adds to its own step (docs/engines.md, the
// Node-hosted engines): each engine on the seed of each of its dimensions in
// per-contact mode at dt = 1e-3, through the harness exactly as `sweep` and
// `stress` run it (a session reused run after run: Node's start-up and the
// engine's load are paid before the timing starts). Two figures per run:
// - engine_ns: the engine's own step, as the adapter times it (the #end
//   line's step_seconds over the steps);
// - overhead_pct: everything else the run cost, as a share of that: the
//   adapter's reads of the state, formatting and writing each row, the pipe,
//   and the harness's parsing, contact detection and recording of the rows.
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
    for (const auto& candidate : all)
        if (candidate->name() == engine) sim = candidate.get();
    const Scenario s = seed_per_contact(dim, engine);
    if (!sim || sim->cannot_run(s)) return state.SkipWithError("cannot run");
    if (record_run(*sim, s).status != RunStatus::ok) return state.SkipWithError("failed");  // the session's start-up
    double wall = 0, step = 0;
    std::int64_t steps = 0;
    for (auto _ : state) {
        const SimulatorSummary r = record_run(*sim, s);
        if (r.status != RunStatus::ok || !r.step_seconds) return state.SkipWithError(r.reason.c_str());
        wall += r.run_seconds;
        step += *r.step_seconds;
        steps += r.steps;
    }
    state.counters["engine_ns"] = step * 1e9 / static_cast<double>(steps);
    state.counters["overhead_pct"] = 100 * (wall - step) / step;
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
