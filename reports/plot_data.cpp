#include "reports/plot_data.h"

#include "simulators/document_clock.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

TraceDecimator::TraceDecimator(std::int64_t expected, std::size_t budget) : stride_(plot_stride(expected, budget)) {}

bool TraceDecimator::reverses(const Vec3& before, const Vec3& after) {
    for (int i = 0; i < 3; ++i)
        if ((before[i] > 0 && after[i] <= 0) || (before[i] < 0 && after[i] >= 0)) return true;
    return false;
}

void TraceDecimator::keep(const State& s) {
    trace_.t.push_back(s.t);
    trace_.p.push_back(s.p);
}

PlotTrace TraceDecimator::finish() {
    if (started_ && !previous_kept_) keep(previous_);
    previous_kept_ = true;
    return trace_;
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

    // The document clock's every sample time, but only the kept samples
    // evaluated: the run's length costs one addition per sample.
    const std::int64_t stride = plot_stride(expected_states(s), budget);
    PlotTrace trace;
    auto keep = [&](double t) {
        trace.t.push_back(t);
        trace.p.push_back(exact.state_at(t).p);
    };
    std::size_t next_event = 0;
    std::int64_t until_kept = 0;
    for (DocumentClock clock(s.dt, s.duration);; clock.advance()) {
        const double t = clock.t();
        while (next_event < events.size() && events[next_event].first < t) {
            trace.t.push_back(events[next_event].first);
            trace.p.push_back(events[next_event].second);
            ++next_event;
        }
        const bool kept = until_kept-- == 0;
        if (kept) {
            keep(t);
            until_kept = stride - 1;
        }
        if (!clock.running()) {
            if (!kept) keep(t);  // the last sample always
            break;
        }
    }
    return trace;
}

}  // namespace bouncecheck
