#include "metrics/summary.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <limits>
#include <span>

namespace bouncecheck {

ContactEvent measure_contact(double t, int axis, int side, const Vec3& v_before, const Vec3& v_after, int dim,
                             unsigned normal_axes) {
    ContactEvent e{t, axis, side, 0.0, std::nan(""), std::abs(v_before[axis])};
    const double normal_in = e.normal_speed_in;
    e.normal_coefficient = normal_in > 0 ? std::abs(v_after[axis]) / normal_in : 0.0;
    double tangential_in = 0, tangential_out = 0;
    for (int i = 0; i < dim; ++i) {
        if (i == axis || ((normal_axes >> i) & 1u)) continue;
        tangential_in += v_before[i] * v_before[i];
        tangential_out += v_after[i] * v_after[i];
    }
    if (std::sqrt(tangential_in) > 1e-9) e.tangential_retention = std::sqrt(tangential_out / tangential_in);
    return e;
}

ImpactVelocities impact_velocities(const State& before, const State& after, int axis, int side, double wall,
                                   const Vec3& gravity) {
    const double step = after.t - before.t;
    // Along the wall's outward normal: the gap from the plane, the speed away
    // from it and gravity's pull, at `after`. Traced back by u >= 0 the flight
    // after is at gap - speed u + pull u^2 / 2.
    const double outward = side < 0 ? 1.0 : -1.0;
    const double gap = outward * (after.p[axis] - wall);
    const double speed = outward * after.v[axis];
    const double pull = outward * gravity[axis];
    double back = 0;  // u at the impact
    if (gap > 0) {
        const double discriminant = speed * speed - 2 * pull * gap;
        const double denominator = discriminant >= 0 ? speed + std::sqrt(discriminant) : 0.0;
        // The nearer root in its cancellation-free form; with none (a pull
        // away from the wall, the plane never reached) the closest approach.
        back = denominator > 0 ? 2 * gap / denominator : (pull > 0 ? speed / pull : step);
        back = std::clamp(back, 0.0, step);
    }
    return {after.t - back, before.v + gravity * (step - back), after.v - gravity * back};
}

StreamRecorder::StreamRecorder(const Scenario& s, StateSink* sink)
    : sink_(sink), dim_(s.dim), vertical_(s.vertical_axis()), walls_(s), gravity_(s.gravity) {
    // The ball has escaped when its centre is beyond a wall's plane: it has
    // sunk into the wall by more than its radius.
    for (int i = 0; i < 3; ++i) {
        low_limit_[i] = i < s.dim ? 0.0 : -std::numeric_limits<double>::infinity();
        high_limit_[i] = i < s.dim ? s.room[i] : std::numeric_limits<double>::infinity();
    }
    // A stepped simulator never rests exactly: the reference micro-bounces
    // forever, fed by one step of gravity per bounce (its steady cycle reaches
    // about (1+alpha)/(1-alpha) |g| dt: 6.8 |g| dt measured for alpha 0.8), and
    // engines jitter at a few |g| dt. Rest is declared when, until the end of
    // the run, the vertical speed stays below k |g| dt and the height above the
    // floor below k^2/2 |g| dt^2 (+1e-6 r), k = (1+alpha)/(1-alpha) within [2, 20].
    const double g = std::abs(s.gravity[vertical_]);
    const double k = s.alpha < 1 ? std::clamp((1 + s.alpha) / (1 - s.alpha), 2.0, 20.0) : 20.0;
    floor_ = s.radius;
    rest_speed_ = k * g * s.dt;
    rest_height_ = 0.5 * k * k * g * s.dt * s.dt + 1e-6 * s.radius;
    dt_ = s.dt;
    stopped_speed_ = s.gravity.norm() * s.dt;
}

void StreamRecorder::diagnose(const State& s) {
    if (!failure_.empty()) return;
    for (int i = 0; i < dim_; ++i) {
        if (!std::isfinite(s.p[i]) || !std::isfinite(s.v[i])) {
            failure_ = fmt::format("non-finite state at t = {:.6g}", s.t);
            return;
        }
        if (s.p[i] < low_limit_[i] || s.p[i] > high_limit_[i]) {
            failure_ = fmt::format("ball left the room at t = {:.6g} (axis {}, centre {:.6g})", s.t, i, s.p[i]);
            return;
        }
    }
}

void StreamRecorder::count_contacts(const State& previous, const State& s, ContactMask contact,
                                    bool after_first_state, const State* before_previous, ContactMask previous_contact) {
    for (int i = 0; i < dim_; ++i) {
        for (const int side : {-1, +1}) {
            if (!(((side < 0 ? contact.lower : contact.upper) >> i) & 1u)) continue;
            ++contacts_;
            if (contact_events_.size() < kKeptContacts && after_first_state) {
                // Both velocities at the impact instant within the step.
                const double wall = side < 0 ? walls_.low[i] : walls_.high[i];
                ImpactVelocities at = impact_velocities(previous, s, i, side, wall, gravity_);
                const bool counted_at_previous = (((side < 0 ? previous_contact.lower : previous_contact.upper) >> i) & 1u) != 0;
                if (before_previous && !counted_at_previous) {
                    // The step before the turn braked the ball's normal speed
                    // beyond what its free flight explains, by more than a step
                    // of gravity and a tenth of that speed (a floor without
                    // gravity), from more than ten steps of gravity (not the
                    // chatter of a ball at rest, whose speeds are a few): the
                    // impact began there, so its normal speed in is that
                    // arrival's. Everything else is compared at the turn's
                    // instant, where the free flight carries it.
                    const double free_speed = side * (before_previous->v[i] + gravity_[i] * (previous.t - before_previous->t));
                    const double braked = free_speed - side * previous.v[i];
                    if (free_speed > 10 * stopped_speed_ && braked > std::max(stopped_speed_, 0.1 * free_speed)) {
                        const ImpactVelocities arrival = impact_velocities(*before_previous, previous, i, side, wall, gravity_);
                        at.incoming = arrival.incoming + gravity_ * (at.t - arrival.t);
                        at.incoming[i] = arrival.incoming[i];
                    }
                }
                const unsigned normal_axes = contact.lower | contact.upper;
                contact_events_.push_back(measure_contact(at.t, i, side, at.incoming, at.outgoing, dim_, normal_axes));
                // Stopped: moving away from the wall slower than a step of gravity would.
                if (-side * at.outgoing[i] <= stopped_speed_)
                    stopped_impacts_.push_back({contact_events_.size() - 1, wall, at.incoming, at.outgoing, normal_axes});
            }
        }
    }
    if ((contact.lower >> vertical_) & 1u) ++floor_contacts_;
}

void StreamRecorder::measure_release(const State& stopped, const State& s) {
    for (const StoppedImpact& impact : stopped_impacts_) {
        ContactEvent& e = contact_events_[impact.event];
        const ImpactVelocities release = impact_velocities(stopped, s, e.axis, e.side, impact.wall, gravity_);
        // Released: now moving away faster than a step of gravity (a ball
        // that stays stopped, at rest, keeps the stop as its outgoing).
        if (-e.side * release.outgoing[e.axis] > stopped_speed_) {
            Vec3 outgoing = impact.outgoing;
            outgoing[e.axis] = release.outgoing[e.axis];
            e = measure_contact(e.t, e.axis, e.side, impact.incoming, outgoing, dim_, impact.normal_axes);
        }
    }
    stopped_impacts_.clear();
}

// The apex sample refined by the parabola through it and its two neighbours
// (samples are dt apart): the vertex, if it lies within a step of the sample.
void StreamRecorder::push_apex(Apex a, double before, double after) {
    const double curvature = before - 2 * a.height + after;  // NaN without both neighbours
    if (curvature < 0) {
        const double offset = 0.5 * dt_ * (before - after) / curvature;
        if (std::abs(offset) <= dt_) {
            a.t += offset;
            a.height -= (after - before) * (after - before) / (8 * curvature);
        }
    }
    if (apexes_.size() < kKeptApexes) apexes_.push_back(a);
    ++apex_count_;
}

WallLimits::WallLimits(const Scenario& s) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
        low[i] = i < s.dim ? s.radius : -inf;
        high[i] = i < s.dim ? s.room[i] - s.radius : inf;
    }
}

void StreamRecorder::record_pending() {
    const std::size_t n = std::exchange(pending_size_, 0);
    if (n == 0) return;
    const std::span<const State> states(pending_states_.data(), n);
    if (sink_) sink_->write_block(states);
    // Each state's predecessor read in place, not copied aside state by state.
    auto track_all = [&]<int D>() {
        Tracking r = tracking_;
        track<D>(r, last_, states[0], pending_contacts_[0]);
        for (std::size_t i = 1; i < n; ++i) track<D>(r, states[i - 1], states[i], pending_contacts_[i]);
        tracking_ = r;
    };
    if (dim_ == 2) track_all.template operator()<2>();
    else track_all.template operator()<3>();
    last_ = states.back();
    check_sound(last_);  // the only state of the block that can be unsound (on_state)
}

void StreamRecorder::on_periodic_tail(const PeriodicTail& tail) {
    record_pending();
    if (tail.count <= 0 || tail.cycle.empty()) return;
    if (sink_) sink_->write_periodic(tail);
    filled_from_ = tail.t_before + tail.dt;
    fill_period_ = tail.period();
    fill_steps_ = tail.count;
    // Replays tail states one by one (the sink has had them already).
    const std::int64_t period = tail.period();
    PeriodicTail::Cursor at(tail);
    auto replay = [&](std::int64_t states) {
        for (std::int64_t i = 0; i < states; ++i) {
            ContactMask contact;
            const State s = at.next(&contact);
            check_sound(s);
            track<3>(tracking_, last_, s, contact);
            last_ = s;
        }
    };
    // What one whole cycle adds to the counts. The recorder has seen the
    // cycle before the tail, so from the tail's start it repeats too.
    const std::int64_t contacts_before = contacts_, floor_before = floor_contacts_, apexes_before = apex_count_;
    replay(std::min(period, at.left()));
    const std::int64_t cycle_contacts = contacts_ - contacts_before;
    const std::int64_t cycle_floor = floor_contacts_ - floor_before;
    const std::int64_t cycle_apexes = apex_count_ - apexes_before;
    // Whole cycles one by one while they still add kept contacts or apexes.
    auto lists_grow = [&] {
        return (cycle_contacts > 0 && contact_events_.size() < kKeptContacts) ||
               (cycle_apexes > 0 && apexes_.size() < kKeptApexes);
    };
    while (at.left() >= 2 * period && lists_grow()) replay(period);
    // Whole cycles counted, not replayed, keeping one whole cycle and the
    // remainder to replay, so that what depends on the times of the last
    // states (rest start, the open apex, the final state) is as stepped.
    const std::int64_t skipped = at.left() / period - 1;
    if (skipped > 0) {
        at.skip(skipped * period);
        tracking_.states += skipped * period;
        contacts_ += skipped * cycle_contacts;
        floor_contacts_ += skipped * cycle_floor;
        apex_count_ += skipped * cycle_apexes;
    }
    replay(at.left());
}

void StreamRecorder::finish(SimulatorSummary& out) {
    record_pending();
    // A last interval whose highest sample is not its final one did turn over.
    if (tracking_.apex_open && tracking_.apex.t < last_.t)
        push_apex(tracking_.apex, tracking_.apex_before, tracking_.apex_after);
    out.steps = tracking_.states > 0 ? tracking_.states - 1 : 0;
    out.contacts = contacts_;
    out.floor_contacts = floor_contacts_;
    out.apexes = apexes_;
    out.contact_events = contact_events_;
    out.max_penetration = tracking_.max_penetration;
    out.energy_max_rise = tracking_.energy_max_rise;
    out.apex_count = apex_count_;
    out.final_state = last_;
    out.filled_from = filled_from_;
    out.fill_period = fill_period_;
    out.fill_steps = fill_steps_;
    // A rest must last: ten steps at least, so that the last samples of a
    // bouncing run do not count.
    const std::optional<double>& rest_since = tracking_.rest_since;
    if (rest_since && last_.t - *rest_since >= kRestSteps * dt_) out.rest_time = rest_since;
    if (!failure_.empty()) {
        out.status = RunStatus::failed;
        out.reason = failure_;
    }
    if (resolved_) {
        out.contacts = resolved_->contacts;
        out.floor_contacts = resolved_->floor_contacts;
        out.contact_events = resolved_->contact_events;
        out.contacts_unbounded = resolved_->contacts_unbounded;
        out.apexes = resolved_->apexes;
        out.apex_count = resolved_->apex_count;
        out.rest_time = resolved_->rest_time;
    }
}

void StreamRecorder::on_resolved_events(const ResolvedEvents& events) {
    Resolved r;
    r.contacts = static_cast<std::int64_t>(events.contacts.size());
    for (const WallContact& c : events.contacts) {
        if (c.axis == vertical_ && c.side < 0) ++r.floor_contacts;
        if (r.contact_events.size() < kKeptContacts)
            r.contact_events.push_back(measure_contact(c.t, c.axis, c.side, c.v_before, c.v_after, dim_));
    }
    r.contacts_unbounded = events.contacts_unbounded;
    for (const Apex& a : events.apexes) {
        if (r.apexes.size() == kKeptApexes) break;
        r.apexes.push_back(a);
    }
    r.apex_count = static_cast<std::int64_t>(events.apexes.size());
    r.rest_time = events.rest_time;
    resolved_ = std::move(r);
}

double SimulatorSummary::ns_per_step() const {
    if (steps <= 0) return step_seconds ? 0.0 : run_seconds * 0.0;  // 0, or NaN when not measured
    return step_seconds.value_or(run_seconds) * 1e9 / static_cast<double>(steps);
}

SimulatorSummary record_run(const Simulator& sim, const Scenario& s, StateSink* sink) {
    SimulatorSummary out;
    out.simulator = std::string(sim.name());
    out.origin = std::string(sim.origin());
    StreamRecorder recorder(s, sink);
    RunOutcome outcome;
    try {
        outcome = sim.run(s, recorder);
    } catch (...) {
        recorder.record_pending();  // the states made before the throw, as the sink would have had them
        throw;
    }
    // The simulator timed its run, streaming included, but the last block
    // is recorded only now.
    const double last_block_seconds = timed_seconds([&] { recorder.record_pending(); });
    recorder.finish(out);
    out.settings = std::move(outcome.settings);
    out.run_seconds = outcome.run_seconds + last_block_seconds;
    out.step_seconds = outcome.step_seconds;
    if (outcome.status != RunStatus::ok) {
        out.status = outcome.status;
        out.reason = std::move(outcome.reason);
    }
    return out;
}

}  // namespace bouncecheck
