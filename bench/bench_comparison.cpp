// What `bouncecheck run` adds to an engine's run: the metrics recorder, the
// reference stepped alongside, exact at every sample, the distance series
// and the decimated path for report.html (run_compared, plots on, no
// trajectory file), against the same engine's unrecorded run (the sweep's
// Simulator::run_unrecorded: the engine loop with its contact screen only).
// The baselines are built once per scenario, outside the timing, as `run`
// builds them once for every simulator.
//
//   taskset -c 1 build/bench/bench_comparison --benchmark_filter='ode|box2d' --benchmark_min_time=3
//
// Target: `overhead_pct` at most 5 for every engine and scenario
// (bench/README.md). Scenarios: the bundled ones, and the seed at
// dt = 1e-3 over 300 s, damped (`long`) and with alpha = beta = 1
// (`elastic`): 300,001 samples, where the per-sample cost dominates.
#include "bench/paired_timing.h"
#include "commands/run/run_pipeline.h"
#include "registry/registry.h"
#include "scenarios/loader.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace bouncecheck;

Scenario bundled(const std::string& file) {
    return load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + file);
}

Scenario lengthened(Scenario s, const std::string& name, bool elastic) {
    s.name = name;
    s.dt = 1e-3;
    s.duration = 300;
    if (elastic) s.alpha = s.beta = 1;
    return s;
}

// Runs `body`; an engine that throws in it (Siconos's event-driven solver
// can) ends this benchmark, not the program. False if it threw.
template <class F>
bool skip_if_it_throws(benchmark::State& state, F&& body) {
    try {
        body();
        return true;
    } catch (const std::exception& e) {
        state.SkipWithError(e.what());
        return false;
    }
}

// Both side by side (bench/paired_timing.h): `overhead_pct` is the median of
// 100 (compared / unrecorded - 1) over the iterations.
void paired(benchmark::State& state, const Simulator& sim, const Scenario& s, const Baselines& base) {
    RunRequest request;
    request.plots = true;
    std::int64_t steps = 1;
    const bench::PairedSeconds t = bench::time_pairs(
        state,
        [&] {
            skip_if_it_throws(state, [&] {
                const UnrecordedRun run = sim.run_unrecorded(s);
                if (run.status != RunStatus::ok) state.SkipWithError(run.reason.c_str());
                steps = std::max<std::int64_t>(run.steps, 1);
                benchmark::DoNotOptimize(run.final_state);
            });
        },
        [&] {
            const ComparedRun run = run_compared(sim, s, request, base);
            if (run.summary.status != RunStatus::ok) state.SkipWithError(run.summary.reason.c_str());
            benchmark::DoNotOptimize(run.vs_exact.rms);
        });
    std::vector<double> ratios, unrecorded_ns, compared_ns;
    for (std::size_t i = 0; i < t.first.size(); ++i) {
        ratios.push_back(t.second[i] / t.first[i]);
        unrecorded_ns.push_back(1e9 * t.first[i] / static_cast<double>(steps));
        compared_ns.push_back(1e9 * t.second[i] / static_cast<double>(steps));
    }
    state.counters["overhead_pct"] = 100 * (bench::median(ratios) - 1);
    state.counters["unrecorded_ns"] = bench::median(unrecorded_ns);
    state.counters["compared_ns"] = bench::median(compared_ns);
    state.counters["pairs"] = static_cast<double>(ratios.size());
}

// The engine's stream played back from memory: timing it compared and
// unrecorded leaves what the harness adds per sample, without the engine's
// own run-to-run noise.
class Replay final : public Simulator {
public:
    Replay(const Simulator& engine, const Scenario& s) : name_(engine.name()) {
        struct Keep final : RunSink {
            bool on_state(const State& st, ContactMask c) override {
                states.push_back({st, c});
                return true;
            }
            void on_periodic_tail(const PeriodicTail& tail) override {
                for (PeriodicTail::Cursor at(tail); at.left() > 0;) {
                    ContactMask c;
                    const State st = at.next(&c);
                    states.push_back({st, c});
                }
            }
            std::vector<std::pair<State, ContactMask>> states;
        } keep;
        engine.run(s, keep);
        states_ = std::move(keep.states);
    }
    std::string_view name() const override { return name_; }
    std::string_view description() const override { return "a recorded stream"; }
    RunOutcome run(const Scenario&, RunSink& sink) const override {
        for (const auto& [st, c] : states_)
            if (!sink.on_state(st, c)) break;
        return {};
    }
    std::int64_t samples() const { return static_cast<std::int64_t>(states_.size()); }

private:
    std::string name_;
    std::vector<std::pair<State, ContactMask>> states_;
};

// What the harness adds per sample: the compared run of a replayed stream
// less its unrecorded run, medians of pairs timed back to back.
void harness(benchmark::State& state, const Replay& replay, const Scenario& s, const Baselines& base) {
    RunRequest request;
    request.plots = true;
    const bench::PairedSeconds t = bench::time_pairs(
        state, [&] { benchmark::DoNotOptimize(replay.run_unrecorded(s).steps); },
        [&] { benchmark::DoNotOptimize(run_compared(replay, s, request, base).vs_exact.rms); });
    std::vector<double> added_ns;
    for (std::size_t i = 0; i < t.first.size(); ++i)
        added_ns.push_back(1e9 * (t.second[i] - t.first[i]) / static_cast<double>(replay.samples()));
    state.counters["added_ns"] = bench::median(added_ns);
}

struct Case {
    Scenario scenario;
    std::unique_ptr<Baselines> base;
};

// The baselines as `bouncecheck run` makes them for every built simulator
// (the track shared), plots on.
std::unique_ptr<Baselines> baselines_for_every_simulator(const Scenario& s,
                                                         const std::vector<std::unique_ptr<const Simulator>>& all) {
    RunRequest request;
    request.plots = true;
    for (const auto& sim : all) request.simulators.push_back(sim.get());
    return std::make_unique<Baselines>(s, request);
}

}  // namespace

int main(int argc, char** argv) {
    static const std::vector<std::unique_ptr<const Simulator>> simulators = built_simulators();
    static std::vector<Case> cases;
    for (const char* file : {"seed-2d.toml", "seed-3d.toml", "seed-2d-per-contact.toml", "seed-3d-per-contact.toml"})
        cases.push_back({bundled(file), nullptr});
    for (const char* seed : {"seed-2d", "seed-3d"}) {
        const Scenario s = bundled(std::string(seed) + ".toml");
        cases.push_back({lengthened(s, std::string(seed) + "-long", false), nullptr});
        cases.push_back({lengthened(s, std::string(seed) + "-elastic", true), nullptr});
    }
    // Built on first use: only the scenarios a filter selects cost their baselines.
    for (Case& c : cases) {
        for (const auto& sim : simulators) {
            if (!sim->third_party() || sim->cannot_run(c.scenario)) continue;
            const std::string name = "Compared/" + std::string(sim->name()) + "/" + c.scenario.name;
            benchmark::RegisterBenchmark(name.c_str(), [&c, &sim = *sim](benchmark::State& st) {
                if (!c.base) c.base = baselines_for_every_simulator(c.scenario, simulators);
                paired(st, sim, c.scenario, *c.base);
            })->Unit(benchmark::kMillisecond);
            benchmark::RegisterBenchmark(("Harness/" + std::string(sim->name()) + "/" + c.scenario.name).c_str(),
                                         [&c, &sim = *sim](benchmark::State& st) {
                                             if (!c.base) c.base = baselines_for_every_simulator(c.scenario, simulators);
                                             static std::map<std::string, std::unique_ptr<Replay>> replays;
                                             auto& replay = replays[std::string(sim.name()) + "/" + c.scenario.name];
                                             if (!replay && !skip_if_it_throws(st, [&] {
                                                     replay = std::make_unique<Replay>(sim, c.scenario);
                                                 }))
                                                 return;
                                             harness(st, *replay, c.scenario, *c.base);
                                         })
                ->Unit(benchmark::kMillisecond);
        }
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
