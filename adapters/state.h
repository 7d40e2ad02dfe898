// One sample of a simulator's output: what every simulator streams.
#pragma once

#include "scenarios/scenario.h"

#include <cstdint>
#include <initializer_list>

namespace bouncecheck {

// Time, ball centre and velocity. In 2D the third components are zero.
struct State {
    double t = 0;
    Vec3 p = Vec3::Zero();
    Vec3 v = Vec3::Zero();
};

// Where a simulator's states go when someone wants them all: a trajectory
// file, or memory (calibration, tests). Runs that need only metrics pass none.
class StateSink {
public:
    virtual ~StateSink() = default;
    virtual void write(const State& s) = 0;
};

// Passes every state to each of a few sinks (null ones are left out).
class TeeSink final : public StateSink {
public:
    TeeSink(std::initializer_list<StateSink*> sinks) {
        for (StateSink* s : sinks)
            if (s && count_ < kMaxSinks) sinks_[count_++] = s;
    }
    void write(const State& s) override {
        for (int i = 0; i < count_; ++i) sinks_[i]->write(s);
    }

private:
    static constexpr int kMaxSinks = 4;
    StateSink* sinks_[kMaxSinks] = {};
    int count_ = 0;
};

// A highest point of the vertical coordinate between floor contacts.
struct Apex {
    double t = 0;
    double height = 0;  // vertical coordinate of the centre
};

// One wall contact with its measured damping (see compare/summary.h).
struct ContactEvent {
    double t = 0;
    int axis = 0;
    int side = -1;                    // -1 lower wall, +1 upper wall
    double normal_coefficient = 0;    // |v_n after| / |v_n before|: alpha in the model
    double tangential_retention = 0;  // |v_t after| / |v_t before|: beta in the model; NaN if undefined
    double normal_speed_in = 0;       // |v_n before|
};

// Walls a simulator reports touching in one step, one bit per axis.
struct ContactMask {
    std::uint8_t lower = 0;
    std::uint8_t upper = 0;
    bool any() const { return (lower | upper) != 0; }
};

}  // namespace bouncecheck
