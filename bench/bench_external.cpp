// What the external protocol costs (docs/external.md): a built simulator run
// in-process (record_run on its Simulator) against the same simulator behind
// the protocol (examples/external/engine_over_protocol.cpp, started as a
// program: JSON in, CSV rows out, each row formatted there and parsed here),
// recorded the same way. The rows are bit-identical (tests/test_external.cpp),
// so the difference is the protocol alone: the program's start-up, once per
// run, and the formatting, pipe and parsing of every row.
//
//   taskset -c 1 build/bench/bench_external --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// Two run lengths per simulator separate the two costs: the per-step cost is
// the slope between them, the start-up the intercept (bench/README.md).
// Imported reads the reference's rows from a file: the harness's share of a
// row (parse and record) without a program. Wall time throughout: the
// program's work happens in another process.
#include "external/external_simulator.h"
#include "metrics/summary.h"
#include "registry/registry.h"
#include "reports/trajectory_csv.h"
#include "scenarios/loader.h"

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <string>

namespace {

using namespace bouncecheck;

Scenario seed3d(double duration) {
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-3d.toml");
    s.dt = 1e-3;  // 42,000 steps at 42 s: long enough that a row's cost shows
    s.duration = duration;
    return s;
}

std::unique_ptr<const Simulator> built(const std::string& name) {
    for (auto& sim : built_simulators())
        if (sim->name() == name) return std::move(sim);
    return nullptr;
}

void measure(benchmark::State& state, const Simulator& sim, const Scenario& s) {
    std::int64_t steps = 0;
    for (auto _ : state) {
        const SimulatorSummary summary = record_run(sim, s);
        if (summary.status != RunStatus::ok) {
            state.SkipWithError(summary.reason.c_str());
            return;
        }
        steps += summary.steps;
        benchmark::DoNotOptimize(summary.final_state);
    }
    state.counters["per_step"] =
        benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// In-process, as `bouncecheck run --in-process` runs it.
void BuiltIn(benchmark::State& state, const std::string& engine, double duration) {
    const auto sim = built(engine);
    if (!sim) return state.SkipWithError(("not built: " + engine).c_str());
    measure(state, *sim, seed3d(duration));
}

// The same simulator through the protocol. Its [engines.<name>] table is the
// built engine's, as the scenario file gives it.
void OverProtocol(benchmark::State& state, const std::string& engine, double duration) {
    Scenario s = seed3d(duration);
    const EngineOptions o = s.engine_options(engine);
    nlohmann::json table = nlohmann::json::object();
    if (o.tangential_model == TangentialModel::friction) table["friction"] = o.friction;
    else table["tangential_model"] = "per-contact";
    s.passthrough_tables[engine + "-ext"] = table.dump();
    const auto sim = make_external_simulator(
        ExternalDeclaration{engine + "-ext", {BOUNCECHECK_ENGINE_EXAMPLE, engine}}, ExternalLimits{});
    measure(state, *sim, s);
}

// The harness's side alone: the reference's rows read back from a file
// (--trajectory), parsed and recorded as the protocol's are.
void Imported(benchmark::State& state, double duration) {
    const Scenario s = seed3d(duration);
    const std::string file = (std::filesystem::temp_directory_path() / "bouncecheck-bench-imported.csv").string();
    {
        TrajectoryCsv csv(file, s.dim);
        record_run(*built("reference"), s, &csv);
        csv.commit();
    }
    measure(state, *make_imported_trajectory("copy", file), s);
    std::filesystem::remove(file);
}

}  // namespace

// reference: the cheapest simulator, so the protocol's share is at its largest.
BENCHMARK_CAPTURE(BuiltIn, reference_42s, std::string("reference"), 42.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(OverProtocol, reference_42s, std::string("reference"), 42.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BuiltIn, reference_420s, std::string("reference"), 420.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(OverProtocol, reference_420s, std::string("reference"), 420.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(Imported, reference_420s, 420.0)->Unit(benchmark::kMillisecond)->UseRealTime();
#ifdef BOUNCECHECK_WITH_ODE
BENCHMARK_CAPTURE(BuiltIn, ode_42s, std::string("ode"), 42.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(OverProtocol, ode_42s, std::string("ode"), 42.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BuiltIn, ode_420s, std::string("ode"), 420.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(OverProtocol, ode_420s, std::string("ode"), 420.0)->Unit(benchmark::kMillisecond)->UseRealTime();
#endif

BENCHMARK_MAIN();
