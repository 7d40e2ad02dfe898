#include "reports/plot_data.h"

#include "simulators/document_clock.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace bouncecheck {

std::int64_t plot_stride(std::int64_t states, std::size_t budget) {
    const std::int64_t b = std::max<std::int64_t>(1, static_cast<std::int64_t>(budget));
    return std::max<std::int64_t>(1, (states + b - 1) / b);
}

std::int64_t expected_states(const Scenario& s) {
    // An estimate is enough for a stride: the document's clock can take one
    // step more or fewer than duration / dt.
    const double steps = std::ceil(std::abs(s.duration / s.dt));
    if (!std::isfinite(steps) || steps > 1e15) return std::numeric_limits<std::int64_t>::max() / 2;
    return static_cast<std::int64_t>(steps) + 1;
}

TraceDecimator::TraceDecimator(std::int64_t expected, int axes, std::size_t budget)
    : stride_(plot_stride(expected, budget)), axes_(axes) {
    // The even samples' share, grown into once rather than by doubling.
    trace_.t.reserve(budget + 1);
    trace_.p.reserve(budget + 1);
}

bool TraceDecimator::reverses(const Vec3& before, const Vec3& after, int axes) {
    for (int i = 0; i < axes; ++i)
        if ((before[i] > 0 && after[i] <= 0) || (before[i] < 0 && after[i] >= 0)) return true;
    return false;
}

void TraceDecimator::write_periodic(const PeriodicTail& tail) {
    PeriodicTail::Cursor at(tail);
    // State by state while a turning point may still be kept: one whole
    // cycle after the first state shows whether the cycle reverses at all.
    const std::int64_t period = tail.period();
    if (at.left() > 0) write(at.next());
    const std::size_t before_cycle = turning_points_;
    for (std::int64_t i = 0; i < period && at.left() > 0; ++i) write(at.next());
    const bool cycle_reverses = turning_points_ != before_cycle;
    while (cycle_reverses && turning_points_ < kPlotTurningPoints && at.left() > 0) write(at.next());
    // From here only the stride keeps states, and the last one is kept by finish().
    while (progress_.until_kept < at.left()) {
        at.skip(progress_.until_kept);
        previous_ = at.next();
        keep(previous_);
        progress_.previous_kept = true;
        progress_.until_kept = stride_ - 1;
    }
    if (at.left() > 0) {
        progress_.until_kept -= at.left();
        at.skip(at.left() - 1);
        previous_ = at.next();
        progress_.previous_kept = false;
    }
}

PlotTrace TraceDecimator::finish() {
    if (progress_.started && !progress_.previous_kept) keep(previous_);
    progress_.previous_kept = true;
    return std::move(trace_);
}

PlotTrace exact_plot_trace(const ExactModel& exact, const Scenario& s, std::size_t budget) {
    // Events first: resolved contacts (where the ball touched) and apexes.
    std::vector<std::pair<double, Vec3>> events;
    for (const WallContact& c : exact.contacts()) {
        if (events.size() >= kPlotTurningPoints) break;
        events.emplace_back(c.t, c.p);
    }
    for (const Apex& a : exact.apexes()) {
        if (events.size() >= 2 * kPlotTurningPoints) break;
        events.emplace_back(a.t, exact.state_at(a.t).p);
    }
    std::sort(events.begin(), events.end(), [](const auto& a, const auto& b) { return a.first < b.first; });

    // The document clock's samples 0, stride, 2 stride, ... and its last,
    // each after the events before it. The clock jumps from one to the next.
    const std::int64_t stride = plot_stride(expected_states(s), budget);
    PlotTrace trace;
    std::size_t next_event = 0;
    auto keep = [&](double t) {
        for (; next_event < events.size() && events[next_event].first < t; ++next_event) {
            trace.t.push_back(events[next_event].first);
            trace.p.push_back(events[next_event].second);
        }
        trace.t.push_back(t);
        trace.p.push_back(exact.state_at(t).p);
    };
    DocumentClock clock(s.dt, s.duration);
    const std::int64_t last = clock.remaining_steps();
    std::int64_t sample = 0;
    for (; sample + stride <= last; sample += stride) {
        keep(clock.t());
        clock.advance(stride);
    }
    keep(clock.t());
    if (sample < last) {
        clock.advance(last - sample);
        keep(clock.t());
    }
    return trace;
}

}  // namespace bouncecheck
