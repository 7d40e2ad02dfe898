// The one interface every simulator implements: reference, exact and the engines.
#pragma once

#include "compare/summary.h"
#include "scenarios/scenario.h"

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

class Simulator {
public:
    virtual ~Simulator() = default;
    virtual std::string_view name() const = 0;
    virtual std::string_view description() const = 0;
    // Why this simulator cannot run `s`, or nothing if it can. Asked before any set-up.
    virtual std::optional<std::string> cannot_run(const Scenario& s) const {
        (void)s;
        return std::nullopt;
    }
    // Runs `s` to its end, streaming states into a recorder (and into `sink`
    // when given). Status, counts, apexes and timing come back.
    virtual SimulatorSummary run(const Scenario& s, StateSink* sink) const = 0;
    // A run that records nothing, for timing (the sweep's cost): only status,
    // reason, steps, final state and run_seconds are filled. A simulator with
    // a cheaper path when no state is wanted overrides it.
    virtual SimulatorSummary run_unrecorded(const Scenario& s) const { return run(s, nullptr); }
    // Runs a library this project does not own (an engine): `run` isolates it
    // in a child process, where an abort costs only its own result.
    virtual bool third_party() const { return false; }
};

// Every simulator this build contains, `reference` and `exact` first.
std::vector<std::unique_ptr<const Simulator>> built_simulators();

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
