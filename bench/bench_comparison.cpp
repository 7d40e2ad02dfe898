// What `bouncecheck run` adds to an engine's run: the metrics recorder, the
// reference stepped alongside, exact at every sample, the distance series
// and the decimated path for report.html (run_compared, plots on, no
// trajectory file), against the same engine's unrecorded run (the sweep's
// Simulator::run_unrecorded: the engine loop with its contact screen only).
// The baselines are built once per scenario, outside the timing, as `run`
// builds them once for every simulator.
//
//   taskset -c 1 build/bench/bench_comparison --benchmark_filter='Compared/(ode|box2d)/' --benchmark_min_time=3
//
// Target: `overhead_pct` at most 5 for every engine and scenario
// (bench/README.md). Scenarios: the bundled ones, and the seed at
// dt = 1e-3 over 300 s, damped (`long`) and with alpha = beta = 1
// (`elastic`): 300,001 samples, where the per-sample cost dominates.
// `Parts/` times pieces of the compared run the same way, to show where an
// engine's 5% goes: the recorder alone, the comparison without plots, and
// two floors (FloorSink).
#include "bench/paired_timing.h"
#include "commands/run/run_pipeline.h"
#include "registry/registry.h"
#include "scenarios/loader.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
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

// The engine's unrecorded run and `recorded` (the same engine's run with
// something on its stream) side by side (bench/paired_timing.h):
// `overhead_pct` is the median of 100 (recorded / unrecorded - 1) over the
// iterations.
template <class Recorded>
void paired(benchmark::State& state, const Simulator& sim, const Scenario& s, Recorded&& recorded) {
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
        recorded);
    std::vector<double> ratios, unrecorded_ns, recorded_ns;
    for (std::size_t i = 0; i < t.first.size(); ++i) {
        ratios.push_back(t.second[i] / t.first[i]);
        unrecorded_ns.push_back(1e9 * t.first[i] / static_cast<double>(steps));
        recorded_ns.push_back(1e9 * t.second[i] / static_cast<double>(steps));
    }
    state.counters["overhead_pct"] = 100 * (bench::median(ratios) - 1);
    state.counters["unrecorded_ns"] = bench::median(unrecorded_ns);
    state.counters["compared_ns"] = bench::median(recorded_ns);
    state.counters["pairs"] = static_cast<double>(ratios.size());
}

// `bouncecheck run`'s path: run_compared, plots on or off.
void compared(benchmark::State& state, const Simulator& sim, const Scenario& s, const Baselines& base,
              bool plots = true) {
    RunRequest request;
    request.plots = plots;
    paired(state, sim, s, [&] {
        const ComparedRun run = run_compared(sim, s, request, base);
        if (run.summary.status != RunStatus::ok) state.SkipWithError(run.summary.reason.c_str());
        benchmark::DoNotOptimize(run.vs_exact.rms);
    });
}

// Floors under the compared run (`Parts/`): what taking the stream a block
// at a time costs with nothing done to it, and with only the arithmetic of
// the two distances (a squared distance, its sum and its maximum, to each
// baseline). Their baselines are a window of 4,096 positions read over and
// over, always in the first-level cache: the values mean nothing, the cost
// is the least any comparison can have.
class FloorSink final : public RunSink {
public:
    static constexpr std::size_t kWindow = 4096;
    FloorSink(const Scenario& s, bool distances) : dim_(s.dim), distances_(distances) {}
    // Like StreamRecorder::on_state: keep the state, test it, take a full block.
    bool on_state(const State& st, ContactMask) override {
        block_[size_] = st;
        bool sound = true;
        for (int i = 0; i < 3; ++i) sound &= std::isfinite(st.p[i]) & std::isfinite(st.v[i]);
        if (++size_ == kBlock || !sound) take_block();
        return true;
    }
    void on_periodic_tail(const PeriodicTail&) override {}
    void take_block() {
        if (distances_) {
            if (dim_ == 2) add_distances<2>();
            else add_distances<3>();
        }
        sample_ += size_;
        size_ = 0;
    }
    struct Window {
        Window() {
            for (std::size_t i = 0; i < kWindow; ++i) {
                reference[i] = Vec3::Constant(0.25 + 1e-9 * static_cast<double>(i));
                exact[i] = Vec3::Constant(0.25 - 1e-9 * static_cast<double>(i));
            }
        }
        std::array<Vec3, kWindow> reference, exact;
    };
    // Made once, before the timing.
    static const Window& window() {
        static const Window made;
        return made;
    }
    double figures() const { return sum_[0] + sum_[1] + max_[0] + max_[1] + static_cast<double>(sample_); }

private:
    static constexpr std::size_t kBlock = 256;
    template <int D>
    void add_distances() {
        const Window& baselines = window();
        double sum_r = sum_[0], sum_e = sum_[1], max_r = max_[0], max_e = max_[1];
        const std::size_t at = sample_ % kWindow;
        for (std::size_t i = 0; i < size_; ++i) {
            const auto p = block_[i].p.head<D>();
            const double r = (p - baselines.reference[(at + i) % kWindow].template head<D>()).squaredNorm();
            const double e = (p - baselines.exact[(at + i) % kWindow].template head<D>()).squaredNorm();
            sum_r += r;
            sum_e += e;
            max_r = std::max(max_r, r);
            max_e = std::max(max_e, e);
        }
        sum_ = {sum_r, sum_e};
        max_ = {max_r, max_e};
    }
    int dim_;
    bool distances_;
    std::array<State, kBlock> block_;
    std::size_t size_ = 0, sample_ = 0;
    std::array<double, 2> sum_{}, max_{};
};

// One part of the compared run, paired with the unrecorded run like
// `Compared/` (see main).
void part(benchmark::State& state, const Simulator& sim, const Scenario& s, const Baselines& base,
          const std::string& which) {
    FloorSink::window();
    if (which == "compared-without-plots") return compared(state, sim, s, base, false);
    if (which == "recorder") {
        return paired(state, sim, s, [&] { benchmark::DoNotOptimize(record_run(sim, s).energy_max_rise); });
    }
    const bool distances = which == "distances-floor";
    paired(state, sim, s, [&] {
        auto sink = std::make_unique<FloorSink>(s, distances);
        sim.run(s, *sink);
        sink->take_block();
        benchmark::DoNotOptimize(sink->figures());
    });
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
                compared(st, sim, c.scenario, *c.base);
            })->Unit(benchmark::kMillisecond);
            for (const char* which : {"blocks-floor", "distances-floor", "recorder", "compared-without-plots"}) {
                const std::string part_name =
                    "Parts/" + std::string(sim->name()) + "/" + c.scenario.name + "/" + which;
                benchmark::RegisterBenchmark(part_name.c_str(), [&c, &sim = *sim, which](benchmark::State& st) {
                    if (!c.base) c.base = baselines_for_every_simulator(c.scenario, simulators);
                    part(st, sim, c.scenario, *c.base, which);
                })->Unit(benchmark::kMillisecond);
            }
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
