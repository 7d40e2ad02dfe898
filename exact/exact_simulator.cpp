// `exact` behind the common simulator interface.
#include "exact/exact_simulator.h"

#include "exact/exact_model.h"

namespace bouncecheck {

namespace {

class ExactSimulator final : public Simulator {
public:
    std::string_view name() const override { return "exact"; }
    std::string_view description() const override {
        return "the same damping law in continuous time: exact parabolas, analytic impacts, Zeno tail summed";
    }
    RunOutcome run(const Scenario& s, RunSink& sink) const override {
        RunOutcome out;
        std::optional<ExactModel> model;
        out.run_seconds = timed_seconds([&] {
            model.emplace(s);
            // Sampled until the ball is still, then the rest handed over as
            // a tail of one repeated state.
            State last;
            const std::optional<DocumentClock> still = model->sample_document_clock_until_still([&](const State& st) {
                sink.on_state(st, ContactMask{});
                last = st;
            });
            if (still) {
                PeriodicTail tail;
                tail.cycle = {last};
                tail.contacts = {ContactMask{}};
                tail.count = remaining_steps(*still);
                tail.t_before = still->t();
                tail.dt = s.dt;
                sink.on_periodic_tail(tail);
            }
        });
        // Contacts and apexes come from the solution itself, not from samples.
        sink.on_resolved_events(ResolvedEvents{model->contacts(), model->apexes(), model->rest_time(),
                                               model->summed_tail_contacts() != 0});
        if (model->event_cap_hit()) {
            // Past the cap the solution is not computed: no ground truth there.
            out.status = RunStatus::failed;
            out.reason = "exact: contact-event cap reached before the end of the run (alpha = 1 pressed into a corner?)";
        }
        return out;
    }
};

}  // namespace

std::unique_ptr<const Simulator> make_exact_simulator() { return std::make_unique<ExactSimulator>(); }

}  // namespace bouncecheck
