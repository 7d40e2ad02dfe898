// `reference` behind the common simulator interface.
#include "reference/reference_simulator.h"

#include "reference/reference_model.h"

namespace bouncecheck {

namespace {

// The reference's recorded run: stepped until its state repeats bit for bit
// (the micro-bounce at rest) and one more period is held, then the rest of
// the run handed over as a periodic tail, not stepped. Every state, count and
// measure is what stepping on would give (tested).
template <int D>
void stream_reference(ReferenceModel<D>& model, RunSink& sink) {
    if (!sink.on_state(model.state(), ContactMask{})) return;
    while (model.running()) {
        const ContactMask contact = model.step_finding_period();
        if (!sink.on_state(model.state(), contact)) return;
        if (!model.cycle_held()) continue;
        if (!model.running()) return;
        PeriodicTail tail;
        tail.cycle = model.held_cycle();
        tail.contacts = model.held_contacts();
        tail.t_before = model.state().t;
        tail.dt = model.dt();
        tail.count = model.remaining_steps();
        sink.on_periodic_tail(tail);
        return;
    }
}

class ReferenceSimulator final : public Simulator {
public:
    std::string_view name() const override { return "reference"; }
    double typical_ns_per_step() const override { return 3; }
    std::string_view description() const override {
        return "the seed document's explicit Euler model, bit for bit";
    }
    RunOutcome run(const Scenario& s, RunSink& sink) const override {
        RunOutcome out;
        out.run_seconds = timed_seconds([&] {
            if (s.dim == 2) {
                ReferenceModel<2> model(s);
                stream_reference(model, sink);
            } else {
                ReferenceModel<3> model(s);
                stream_reference(model, sink);
            }
        });
        return out;
    }
    // The model alone, to the end: the free-flight loop, and the periodic
    // rest counted rather than stepped (ReferenceModel::run_to_end).
    UnrecordedRun run_unrecorded(const Scenario& s) const override {
        UnrecordedRun out;
        const auto run = [&](auto& model) {
            out.run_seconds = timed_seconds([&] { model.run_to_end(); });
            out.steps = model.steps();
            out.final_state = model.state();
        };
        if (s.dim == 2) {
            ReferenceModel<2> model(s);
            run(model);
        } else {
            ReferenceModel<3> model(s);
            run(model);
        }
        return out;
    }
};

}  // namespace

std::unique_ptr<const Simulator> make_reference_simulator() { return std::make_unique<ReferenceSimulator>(); }

}  // namespace bouncecheck
