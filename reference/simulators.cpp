// `reference` and `exact` behind the common simulator interface.
#include "reference/simulators.h"

#include "reference/exact_model.h"
#include "reference/reference_model.h"

namespace bouncecheck {

namespace {

// The reference's recorded run: stepped until its state repeats bit for bit
// (the micro-bounce at rest) and one more period is held, then the rest of
// the run handed over as a periodic tail, not stepped. Every state, count and
// measure is what stepping on would give (tested).
template <int D>
void record_reference(ReferenceModel<D>& model, StreamRecorder& recorder) {
    recorder.on_state(model.state(), ContactMask{});
    while (model.running() && !recorder.failed()) {
        const ContactMask contact = model.step_finding_period();
        recorder.on_state(model.state(), contact);
        if (!model.cycle_held()) continue;
        if (!model.running()) return;
        PeriodicTail tail;
        tail.cycle = model.held_cycle();
        tail.contacts = model.held_contacts();
        tail.t_before = model.state().t;
        tail.dt = model.dt();
        tail.count = model.remaining_steps();
        recorder.on_periodic_tail(tail);
        return;
    }
}

class ReferenceSimulator final : public Simulator {
public:
    std::string_view name() const override { return "reference"; }
    std::string_view description() const override {
        return "the seed document's explicit Euler model, bit for bit";
    }
    SimulatorSummary run(const Scenario& s, StateSink* sink) const override {
        SimulatorSummary out;
        out.simulator = std::string(name());
        StreamRecorder recorder(s, sink);
        out.run_seconds = timed_seconds([&] {
            if (s.dim == 2) {
                ReferenceModel<2> model(s);
                record_reference(model, recorder);
            } else {
                ReferenceModel<3> model(s);
                record_reference(model, recorder);
            }
        });
        recorder.finish(out);
        return out;
    }
    // The model alone, to the end: the free-flight loop, and the periodic
    // rest counted rather than stepped (ReferenceModel::run_to_end).
    SimulatorSummary run_unrecorded(const Scenario& s) const override {
        SimulatorSummary out;
        out.simulator = std::string(name());
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

class ExactSimulator final : public Simulator {
public:
    std::string_view name() const override { return "exact"; }
    std::string_view description() const override {
        return "the same damping law in continuous time: exact parabolas, analytic impacts, Zeno tail summed";
    }
    SimulatorSummary run(const Scenario& s, StateSink* sink) const override {
        SimulatorSummary out;
        out.simulator = std::string(name());
        StreamRecorder recorder(s, sink);
        std::optional<ExactModel> model;
        out.run_seconds = timed_seconds([&] {
            model.emplace(s);
            // Sampled until the ball is still, then the rest handed over as
            // a tail of one repeated state.
            State last;
            const std::optional<DocumentClock> still = model->sample_document_clock_until_still([&](const State& st) {
                recorder.on_state(st, ContactMask{});
                last = st;
            });
            if (still) {
                PeriodicTail tail;
                tail.cycle = {last};
                tail.contacts = {ContactMask{}};
                tail.count = remaining_steps(*still);
                tail.t_before = still->t();
                tail.dt = s.dt;
                recorder.on_periodic_tail(tail);
            }
        });
        recorder.finish(out);
        // Contacts and apexes come from the solution itself, not from samples.
        const int vertical = s.vertical_axis();
        out.contacts = static_cast<std::int64_t>(model->contacts().size());
        out.floor_contacts = 0;
        out.contact_events.clear();
        for (const Contact& c : model->contacts()) {
            if (c.axis == vertical && c.side < 0) ++out.floor_contacts;
            if (out.contact_events.size() < kKeptContacts)
                out.contact_events.push_back(measure_contact(c.t, c.axis, c.side, c.v_before, c.v_after, s.dim));
        }
        out.contacts_unbounded = model->summed_tail_contacts() != 0;
        out.apexes.clear();
        for (const auto& a : model->apexes()) {
            if (out.apexes.size() == kKeptApexes) break;
            out.apexes.push_back(Apex{a.t, a.height});
        }
        out.apex_count = static_cast<std::int64_t>(model->apexes().size());
        out.rest_time = model->rest_time();
        if (model->event_cap_hit()) {
            // Past the cap the solution is not computed: no ground truth there.
            out.status = RunStatus::failed;
            out.reason = "exact: contact-event cap reached before the end of the run (alpha = 1 pressed into a corner?)";
        }
        return out;
    }
};

}  // namespace

std::unique_ptr<const Simulator> make_reference_simulator() { return std::make_unique<ReferenceSimulator>(); }
std::unique_ptr<const Simulator> make_exact_simulator() { return std::make_unique<ExactSimulator>(); }

}  // namespace bouncecheck
