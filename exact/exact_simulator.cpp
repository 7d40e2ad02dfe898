// `exact` behind the common simulator interface.
#include "exact/exact_simulator.h"

#include "exact/exact_model.h"

#include <fmt/format.h>

namespace bouncecheck {

namespace {

class ExactSimulator final : public Simulator {
public:
    std::string_view name() const override { return "exact"; }
    // Its samples until the ball is still; the rest is a tail, free.
    double typical_ns_per_step() const override { return 20; }
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
                tail.count = still->remaining_steps();
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
            const double at = model->contacts().empty() ? 0.0 : model->contacts().back().t;
            if (const auto scale = model->stalled_corner())
                out.reason = fmt::format(
                    "exact: gave up at t = {:.9g} s after {} contact events (the cap): alpha = 1 and beta = {} hold "
                    "the ball in a corner cycle that stopped shrinking (time scale {:.3g} s: each contact comes at "
                    "the other wall's turning point and loses almost no energy); past it there is no ground truth "
                    "(docs/models.md)",
                    at, ExactModel::kDefaultMaxEvents, s.beta, *scale);
            else
                out.reason = fmt::format(
                    "exact: gave up at t = {:.9g} s after {} contact events (the cap), before the end of the run; "
                    "past it there is no ground truth (docs/models.md: an elastic wall holding the ball, or more "
                    "real contacts than the cap)",
                    at, ExactModel::kDefaultMaxEvents);
        }
        return out;
    }
};

}  // namespace

std::unique_ptr<const Simulator> make_exact_simulator() { return std::make_unique<ExactSimulator>(); }

}  // namespace bouncecheck
