// One sample of a simulator's output: what every simulator streams.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/repeated_addition.h"

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

namespace bouncecheck {

// Time, ball centre and velocity. In 2D the third components are zero.
struct State {
    double t = 0;
    Vec3 p = Vec3::Zero();
    Vec3 v = Vec3::Zero();
};

// Walls a simulator reports touching in one step, one bit per axis.
struct ContactMask {
    std::uint8_t lower = 0;
    std::uint8_t upper = 0;
    bool any() const { return (lower | upper) != 0; }
};

// The rest of a run whose states have become periodic (the reference's
// micro-bounce at rest repeats bit for bit; exact at rest is constant): tail
// state k (k = 0 .. count - 1) has the position, velocity and contacts of
// cycle[k % cycle.size()] and the time t_k = t_{k-1} + dt from t_{-1} =
// t_before, the document clock's own additions. A simulator hands this over
// instead of stepping on (RunSink::on_periodic_tail).
struct PeriodicTail {
    std::vector<State> cycle;           // t unused
    std::vector<ContactMask> contacts;  // per cycle state
    std::int64_t count = 0;
    double t_before = 0, dt = 0;
    std::int64_t period() const { return static_cast<std::int64_t>(cycle.size()); }

    // Walks the tail in order: next() makes the next state, skip(n) goes
    // past n of them in O(log n).
    class Cursor {
    public:
        explicit Cursor(const PeriodicTail& tail) : tail_(&tail), t_(tail.t_before) {}
        std::int64_t left() const { return tail_->count - done_; }
        std::size_t phase() const { return phase_; }  // the next state's place in the cycle
        double next_t() const { return t_ + tail_->dt; }
        State next(ContactMask* contact = nullptr) {
            State s = tail_->cycle[phase_];
            if (contact) *contact = tail_->contacts[phase_];
            t_ = t_ + tail_->dt;
            s.t = t_;
            if (++phase_ == tail_->cycle.size()) phase_ = 0;
            ++done_;
            return s;
        }
        // The time of the state `ahead` states after the next one.
        double t_ahead(std::int64_t ahead) const { return sum_after(t_, tail_->dt, ahead + 1); }
        // How many of the states left have a time before `limit`.
        std::int64_t left_before(double limit) const {
            const auto to_reach = additions_to_reach(t_, tail_->dt, limit, left());
            return to_reach ? std::max<std::int64_t>(*to_reach - 1, 0) : left();
        }
        void skip(std::int64_t n) {
            t_ = sum_after(t_, tail_->dt, n);
            phase_ = static_cast<std::size_t>((static_cast<std::int64_t>(phase_) + n % tail_->period()) %
                                              tail_->period());
            done_ += n;
        }

    private:
        const PeriodicTail* tail_;
        double t_;
        std::size_t phase_ = 0;
        std::int64_t done_ = 0;
    };
};

// Where a run's states go when someone wants them all: a trajectory file,
// the comparison, the plot, or memory (calibration, tests). The metrics
// recorder passes each state on to one (metrics/summary.h); runs that need
// only metrics pass none.
class StateSink {
public:
    virtual ~StateSink() = default;
    virtual void write(const State& s) = 0;
    // Consecutive states of the stream, in order (the metrics recorder passes
    // them in blocks). By default each one is written; a sink whose per-state
    // work is worth fusing over a block overrides this, with the same result.
    virtual void write_block(std::span<const State> states) {
        for (const State& s : states) write(s);
    }
    // The run's remaining states, periodic. By default each one is written;
    // a sink that can take them faster overrides this, with the same result.
    virtual void write_periodic(const PeriodicTail& tail) {
        for (PeriodicTail::Cursor at(tail); at.left() > 0;) write(at.next());
    }
};

// A highest point of the vertical coordinate between floor contacts.
struct Apex {
    double t = 0;
    double height = 0;  // vertical coordinate of the centre
};

// A wall contact at its instant, as a simulator that resolves contacts in
// continuous time knows it (exact): the centre and the velocity on both sides.
struct WallContact {
    double t = 0;
    int axis = 0;
    int side = -1;  // -1 lower wall (p = r), +1 upper wall (p = size - r)
    Vec3 p = Vec3::Zero(), v_before = Vec3::Zero(), v_after = Vec3::Zero();
};

}  // namespace bouncecheck
