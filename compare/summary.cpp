#include "compare/summary.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>

namespace bouncecheck {

const char* to_string(RunStatus s) {
    switch (s) {
        case RunStatus::ok: return "ok";
        case RunStatus::skipped: return "skipped";
        case RunStatus::failed: return "failed";
    }
    return "?";
}

StreamRecorder::StreamRecorder(const Scenario& s, StateSink* sink)
    : sink_(sink), dim_(s.dim), vertical_(s.vertical_axis()) {
    // The ball has escaped when its centre is beyond a wall's plane: it has
    // sunk into the wall by more than its radius.
    low_limit_ = Vec3::Zero();
    high_limit_ = s.room;
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
}

void StreamRecorder::check(const State& s) {
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

void StreamRecorder::count_contacts(const State& s, ContactMask contact) {
    contacts_ += std::popcount(static_cast<unsigned>(contact.lower)) +
                 std::popcount(static_cast<unsigned>(contact.upper));
    if ((contact.lower >> vertical_) & 1u) {
        ++floor_contacts_;
        if (floor_contacts_seen_.size() < kReportedApexes && states_ > 0) {
            const double incoming = std::abs(last_.v[vertical_]);
            floor_contacts_seen_.push_back(
                {s.t, incoming > 0 ? std::abs(s.v[vertical_]) / incoming : 0.0});
        }
        // The interval since the previous floor contact closes: its highest
        // sample is an apex unless the ball never rose above the floor sample.
        if (apex_open_ && apex_.t < s.t) push_apex(apex_);
        apex_open_ = false;
    }
}

void StreamRecorder::push_apex(const Apex& a) {
    if (apexes_.size() < kReportedApexes) apexes_.push_back(a);
    ++apex_count_;
}

void StreamRecorder::finish(SimulatorSummary& out) {
    // A last interval whose highest sample is not its final one did turn over.
    if (apex_open_ && apex_.t < last_.t) push_apex(apex_);
    out.steps = states_ > 0 ? states_ - 1 : 0;
    out.contacts = contacts_;
    out.floor_contacts = floor_contacts_;
    out.apexes = apexes_;
    out.first_floor_contacts = floor_contacts_seen_;
    out.apex_count = apex_count_;
    out.final_state = last_;
    // A rest must last: ten steps at least, so that the last samples of a
    // bouncing run do not count.
    if (rest_since_ && last_.t - *rest_since_ >= kRestSteps * dt_) out.rest_time = rest_since_;
    if (!failure_.empty()) {
        out.status = RunStatus::failed;
        out.reason = failure_;
    }
}

}  // namespace bouncecheck
