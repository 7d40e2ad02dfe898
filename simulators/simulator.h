// The one interface every simulator implements: reference, exact and the
// engines. As MuJoCo keeps its immutable mjModel apart from the mjData a step
// fills, a simulator reads the validated Scenario and streams what it does
// into a RunSink the caller passes in: it knows nothing of the metrics,
// comparisons or reports made from its stream.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/state.h"

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

enum class RunStatus { ok, skipped, failed };
const char* to_string(RunStatus s);

// A setting that changes the answer, as used (engine version, precision,
// restitution and friction and their combine rules, thresholds, slop,
// sleeping, scale...): key, value, and why it was chosen.
struct Setting {
    std::string key, value, why;
};

// What a simulator solved at the instants themselves rather than sampled
// (exact): they stand in for what its samples show.
struct ResolvedEvents {
    std::span<const WallContact> contacts;  // every resolved contact, in time order
    std::span<const Apex> apexes;           // every resolved apex, in time order
    std::optional<double> rest_time;        // the vertical motion ends on the floor here
    bool contacts_unbounded = false;        // infinitely many Zeno contacts summed in closed form
};

// Where a simulator streams a run, state by state from the initial one on.
class RunSink {
public:
    virtual ~RunSink() = default;
    // A state and the walls touched in the step that made it. Returns false
    // once the run should stop (a state that ends it: non-finite, or outside
    // the room).
    virtual bool on_state(const State& s, ContactMask contact) = 0;
    // The run's remaining states, periodic (see PeriodicTail): the simulator
    // stops stepping here.
    virtual void on_periodic_tail(const PeriodicTail& tail) = 0;
    // Once, after the last state, from a simulator that resolves its contacts
    // and apexes at their instants.
    virtual void on_resolved_events(const ResolvedEvents& events) { (void)events; }
};

// What only the simulator knows of its run (everything else is in its stream).
struct RunOutcome {
    RunStatus status = RunStatus::ok;  // failed: the simulator itself gave up
    std::string reason;                // why
    std::vector<Setting> settings;     // every setting that changes the answer
    double run_seconds = 0;            // wall time of the run, streaming included
    // The engine's own steps, as the simulator timed them, where it says (an
    // external program's #end line): its cost without start-up or streaming.
    std::optional<double> step_seconds;
};

// A run that streamed nothing, for timing: where it ended and what it cost.
struct UnrecordedRun {
    RunStatus status = RunStatus::ok;
    std::string reason;
    std::int64_t steps = 0;
    State final_state;
    double run_seconds = 0;
    std::optional<double> step_seconds;  // as RunOutcome's
};

class Simulator {
public:
    virtual ~Simulator() = default;
    virtual std::string_view name() const = 0;
    virtual std::string_view description() const = 0;
    // Where a simulator bouncecheck did not build comes from ("external:
    // COMMAND", "imported: FILE"); empty for a built one.
    virtual std::string_view origin() const { return {}; }
    // Why this simulator cannot run `s`, or nothing if it can. Asked before any set-up.
    virtual std::optional<std::string> cannot_run(const Scenario& s) const {
        (void)s;
        return std::nullopt;
    }
    // Runs `s` to its end (or until `sink` says stop), streaming every state into `sink`.
    virtual RunOutcome run(const Scenario& s, RunSink& sink) const = 0;
    // A run that streams nothing, for timing (the sweep's cost). By default
    // run() into a sink that keeps only the count and the last state; a
    // simulator with a cheaper path when no state is wanted overrides it.
    virtual UnrecordedRun run_unrecorded(const Scenario& s) const;
    // Runs a library this project does not own (an engine): `run` isolates it
    // in a child process, where an abort costs only its own result.
    virtual bool third_party() const { return false; }
    // Its engine already runs in a program of its own (the Node-hosted
    // engines): an abort there costs only its own result, and `run` keeps it
    // in this process, where its program serves every scenario of the run
    // (with --budget it goes to the workers, whose deadline enforces that).
    virtual bool runs_in_own_program() const { return false; }
    // What one step typically costs (ns), for scheduling only: the costliest
    // pairs start first (platform/parallel_pairs.h). The engines' figures are
    // medians of `sweep seed-2d --jobs 1` on the development machine; a
    // simulator that does not know counts as 1 us.
    virtual double typical_ns_per_step() const { return 1000; }
};

// Keeps every state in memory.
class StateVector final : public StateSink {
public:
    void write(const State& s) override { states.push_back(s); }
    std::vector<State> states;
};

// Wall-clock seconds spent in `body()`.
template <class F>
double timed_seconds(F&& body) {
    const auto start = std::chrono::steady_clock::now();
    body();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace bouncecheck
