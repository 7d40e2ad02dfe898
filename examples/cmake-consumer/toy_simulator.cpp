#include "toy_simulator.h"

#include <charconv>
#include <cstdint>
#include <utility>

namespace toy {

namespace {

using bouncecheck::ContactMask;
using bouncecheck::Scenario;
using bouncecheck::State;
using bouncecheck::Vec3;

// The shortest text that reads back to the same double.
std::string shortest(double x) {
    char buffer[32];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, x);
    return ec == std::errc{} ? std::string(buffer, end) : std::string("?");
}

// One step of dt: v += g dt, then p += v dt (the new velocity moves the
// ball), then the law's damping at each wall the centre passed while moving
// into it. Returns the walls touched, one bit per axis.
ContactMask step(State& state, const Scenario& s, double alpha, const Vec3& low, const Vec3& high) {
    const int dim = s.dim;
    for (int i = 0; i < dim; ++i) state.v[i] += s.gravity[i] * s.dt;
    ContactMask contact;
    for (int i = 0; i < dim; ++i) {
        state.p[i] += state.v[i] * s.dt;
        // A centre beyond a wall is put back on it; the wall is touched only
        // if the ball moves into it (one leaving it is not bounced back).
        if (state.p[i] < low[i]) {
            state.p[i] = low[i];
            if (state.v[i] < 0) contact.lower |= static_cast<std::uint8_t>(1u << i);
        } else if (state.p[i] > high[i]) {
            state.p[i] = high[i];
            if (state.v[i] > 0) contact.upper |= static_cast<std::uint8_t>(1u << i);
        }
    }
    if (contact.any()) {
        // Each touched wall reverses its own normal component, scaled by
        // alpha (at a corner, several); every other component is scaled by
        // beta, once.
        const unsigned touched = contact.lower | contact.upper;
        for (int i = 0; i < dim; ++i) state.v[i] *= ((touched >> i) & 1u) ? -alpha : s.beta;
    }
    return contact;
}

// The run on the document's clock: the initial state, then one state per
// step while |t| < |duration|, t advancing by the same additions of dt.
void stream(const Scenario& s, double alpha, bouncecheck::RunSink& sink) {
    Vec3 low = Vec3::Zero(), high = Vec3::Zero();
    for (int i = 0; i < s.dim; ++i) {
        low[i] = s.radius;
        high[i] = s.room[i] - s.radius;
    }
    State state;
    state.t = 0.0;
    state.p = s.position;
    state.v = s.velocity;
    if (!sink.on_state(state, ContactMask{})) return;
    bouncecheck::DocumentClock clock(s.dt, s.duration);
    while (clock.running()) {
        const ContactMask contact = step(state, s, alpha, low, high);
        clock.advance();
        state.t = clock.t();
        if (!sink.on_state(state, contact)) return;  // the harness ends the run
    }
}

}  // namespace

SemiImplicitEuler::SemiImplicitEuler(std::optional<double> alpha_override, std::string name)
    : alpha_override_(alpha_override), name_(std::move(name)) {
    description_ = "semi-implicit Euler with the law's per-contact damping (examples/cmake-consumer)";
    if (alpha_override_)
        description_ += ", deliberately wrong: alpha " + shortest(*alpha_override_) + " whatever the scenario says";
}

bouncecheck::RunOutcome SemiImplicitEuler::run(const Scenario& s, bouncecheck::RunSink& sink) const {
    const double alpha = alpha_override_.value_or(s.alpha);
    bouncecheck::RunOutcome out;
    out.settings = {
        {"engine", "toy::SemiImplicitEuler", "the example simulator of examples/cmake-consumer"},
        {"integrator", "semi-implicit Euler", "v += g dt, then p += v dt: the new velocity moves the ball"},
        {"contact", "per-contact damping",
         "normal component reversed and scaled by alpha, every other scaled by beta, once per step"},
        {"position_at_contact", "on the wall (centre at r)", "as the reference clamps it: no sample overlaps a wall"},
        {"alpha", shortest(alpha),
         alpha_override_ ? "overridden in the constructor: a deliberately wrong simulator" : "the scenario's"},
        {"beta", shortest(s.beta), "the scenario's"},
    };
    out.run_seconds = bouncecheck::timed_seconds([&] { stream(s, alpha, sink); });
    return out;
}

}  // namespace toy
