// What report.html plots of a run, recorded while the simulators stream:
// trajectories decimated so the page stays light, and the distance to the
// reference and to exact over time. Memory is bounded by the point budget,
// not by the run's length.
#pragma once

#include "exact/exact_model.h"
#include "scenarios/scenario.h"
#include "simulators/state.h"

#include <bit>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace bouncecheck {

// About this many evenly spaced samples per trace, plus the kept turning points.
inline constexpr std::size_t kPlotPoints = 600;
// Turning points (contacts, apexes) kept beyond the even samples, per trace:
// a ball jittering on the floor reverses every step, and that must not grow
// the page without bound.
inline constexpr std::size_t kPlotTurningPoints = 3000;

struct PlotTrace {
    std::vector<double> t;
    std::vector<Vec3> p;
    std::size_t size() const { return t.size(); }
};

// Keeps every stride-th state, and both states around every reversal of a
// velocity component (a contact or an apex), so the decimated path still
// shows each bounce where it happened. The last state is always kept.
class TraceDecimator final : public StateSink {
public:
    // expected_states: how many states the run will stream (sets the
    // stride); axes: the scene's (Scenario::dim), the only ones whose
    // reversals are turning points (a 2D scene's third axis is not drawn).
    TraceDecimator(std::int64_t expected_states, int axes, std::size_t budget = kPlotPoints);
    void write(const State& s) override { write_block({&s, 1}); }
    void write_block(std::span<const State> states) override {
        if (states.empty()) return;
        if (axes_ == 2) take_all<2>(states);
        else take_all<3>(states);
    }
    // The same kept states as write() of each, in O(period x turning
    // points kept + kept states x log) instead of O(states).
    void write_periodic(const PeriodicTail& tail) override;
    // The kept path, the last state included; once, after the last write.
    PlotTrace finish();

private:
    struct Progress {
        std::int64_t until_kept = 0;  // states until the next one on the stride
        bool started = false, previous_kept = false;
    };
    // Each state's predecessor read in place rather than copied aside, the
    // countdown and flags in locals for the block (as members, every state
    // stored and reloaded them). D: the scene's axes.
    template <int D>
    void take_all(std::span<const State> states) {
        Progress progress = progress_;
        const State* previous = &previous_;
        for (const State& s : states) {
            take<D>(progress, *previous, s);
            previous = &s;
        }
        progress_ = progress;
        previous_ = states.back();
    }
    // One state, after `previous` (the stream's state before it; unused
    // for the first). Inline, every state: a countdown rather than a
    // division for the stride, and one branch-free screen for a reversal.
    template <int D>
    void take(Progress& at, const State& previous, const State& s) {
        // A component that was nonzero and now has the other sign or is
        // zero, read from the bits: a ball at rest keeps subnormal
        // tangential velocities for about 1e5 states, and a product of two
        // takes the processor's slow path (it was half of this function's
        // time). A NaN can pass the screen; reverses() decides (rarely
        // asked: contacts and apexes).
        constexpr std::uint64_t kMagnitude = 0x7FFF'FFFF'FFFF'FFFFull;
        std::uint64_t screen = 0;
        for (int i = 0; i < D; ++i) {
            const auto before = std::bit_cast<std::uint64_t>(previous.v[i]);
            const auto after = std::bit_cast<std::uint64_t>(s.v[i]);
            const std::uint64_t sign_flips = (before ^ after) >> 63, now_zero = (after & kMagnitude) == 0;
            screen |= static_cast<std::uint64_t>((before & kMagnitude) != 0) & (sign_flips | now_zero);
        }
        const bool turning =
            screen && at.started && turning_points_ < kPlotTurningPoints && reverses(previous.v, s.v, D);
        if (turning) {
            // The state before the reversal too: the path's corner lies between them.
            if (!at.previous_kept) keep(previous);
            turning_points_ += 2;
        }
        const bool on_stride = at.until_kept-- == 0;
        if (on_stride) at.until_kept = stride_ - 1;
        const bool kept = turning || on_stride;
        if (kept) keep(s);
        at.previous_kept = kept;
        at.started = true;
    }
    static bool reverses(const Vec3& before, const Vec3& after, int axes);
    void keep(const State& s) {
        trace_.t.push_back(s.t);
        trace_.p.push_back(s.p);
    }
    std::int64_t stride_;
    int axes_;
    std::size_t turning_points_ = 0;
    State previous_;
    Progress progress_;
    PlotTrace trace_;
};

// The exact path to draw: the document-clock samples with every resolved
// contact and apex inserted at its instant, so the corners are sharp. At most
// `budget` document samples (decimated evenly) and kPlotTurningPoints events.
PlotTrace exact_plot_trace(const ExactModel& exact, const Scenario& s, std::size_t budget = kPlotPoints);

// The states a scenario's run streams on the document clock (initial one included).
std::int64_t expected_states(const Scenario& s);
// Every how many states a plotted series keeps one, for about `budget` of them.
std::int64_t plot_stride(std::int64_t states, std::size_t budget = kPlotPoints);

}  // namespace bouncecheck
