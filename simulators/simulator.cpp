#include "simulators/simulator.h"

namespace bouncecheck {

const char* to_string(RunStatus s) {
    switch (s) {
        case RunStatus::ok: return "ok";
        case RunStatus::skipped: return "skipped";
        case RunStatus::failed: return "failed";
    }
    return "?";
}

namespace {

// Counts the states and keeps the last one, nothing else.
class FinalStateSink final : public RunSink {
public:
    bool on_state(const State& s, ContactMask) override {
        last = s;
        ++states;
        return true;
    }
    void on_periodic_tail(const PeriodicTail& tail) override {
        if (tail.count <= 0) return;
        PeriodicTail::Cursor at(tail);
        at.skip(tail.count - 1);
        on_state(at.next(), ContactMask{});
        states += tail.count - 1;
    }
    State last;
    std::int64_t states = 0;
};

}  // namespace

UnrecordedRun Simulator::run_unrecorded(const Scenario& s) const {
    FinalStateSink sink;
    const RunOutcome outcome = run(s, sink);
    return UnrecordedRun{outcome.status, outcome.reason, sink.states > 0 ? sink.states - 1 : 0, sink.last,
                         outcome.run_seconds, outcome.step_seconds};
}

}  // namespace bouncecheck
