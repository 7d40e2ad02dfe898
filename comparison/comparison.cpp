#include "comparison/comparison.h"

#include "reference/reference_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

namespace bouncecheck {

// Running distance statistics against one baseline, kept on squared
// distances: the sum of squares needs no square root, and the largest
// distance is the root of the largest square (sqrt is monotone and
// correctly rounded), so a sample costs no root unless it may be the first
// beyond the tolerance.
struct TrajectoryComparer::Stats {
    explicit Stats(std::optional<double> rest)
        : cut(rest.value_or(std::numeric_limits<double>::infinity())),
          // Below this no distance exceeds the tolerance (a margin for the
          // rounding of the square).
          screen(0.999 * kDivergenceTolerance * kDivergenceTolerance) {
        result.rest_cut = rest;
    }
    void add(double t, double squared) {
        sum_sq += squared;
        ++samples;
        max_sq = std::max(max_sq, squared);
        if (t < cut) {
            sum_sq_before += squared;
            ++samples_before;
            max_sq_before = std::max(max_sq_before, squared);
        }
        if (!result.first_exceeds && exceeds(squared)) result.first_exceeds = t;
    }
    bool exceeds(double squared) const { return squared > screen && std::sqrt(squared) > result.tolerance; }
    // The rest of a periodic tail whose squared distances repeat `cycle`
    // from the next sample on: what add() of each gives, bit for bit, in
    // O(cycle x log) (simulators/repeated_addition.h).
    void add_periodic(const PeriodicTail::Cursor& at, std::span<const double> cycle) {
        const std::int64_t n = at.left(), before = at.left_before(cut);
        const auto period = static_cast<std::int64_t>(cycle.size());
        auto largest = [&](std::int64_t count) {
            return *std::max_element(cycle.begin(), cycle.begin() + std::min(count, period));
        };
        sum_sq = sum_after(sum_sq, cycle, 0, n);
        samples += n;
        max_sq = std::max(max_sq, largest(n));
        if (before > 0) {
            sum_sq_before = sum_after(sum_sq_before, cycle, 0, before);
            samples_before += before;
            max_sq_before = std::max(max_sq_before, largest(before));
        }
        for (std::int64_t j = 0; j < std::min(n, period) && !result.first_exceeds; ++j) {
            if (exceeds(cycle[static_cast<std::size_t>(j)])) result.first_exceeds = at.t_ahead(j);
        }
    }
    TrajectoryDivergence finished() const {
        TrajectoryDivergence out = result;
        out.samples = samples;
        out.max = std::sqrt(max_sq);
        out.max_before_rest = std::sqrt(max_sq_before);
        if (samples > 0) out.rms = std::sqrt(sum_sq / static_cast<double>(samples));
        if (samples_before > 0) out.rms_before_rest = std::sqrt(sum_sq_before / static_cast<double>(samples_before));
        return out;
    }
    TrajectoryDivergence result;
    double cut, screen;
    double sum_sq = 0, sum_sq_before = 0, max_sq = 0, max_sq_before = 0;
    std::int64_t samples = 0, samples_before = 0;
};

// The reference in lockstep with the compared stream: its sample n is at the
// same document-clock time as the stream's sample n. It is stepped until its
// state repeats bit for bit (its rest) and the model holds one more period
// (step_finding_period), which it replays from there on instead of stepping.
struct TrajectoryComparer::LockstepReference {
    template <int D>
    struct Replaying {
        explicit Replaying(const Scenario& s) : model(s) {}
        Vec3 next_position() {
            if (!started) {
                started = true;
                return model.state().p;
            }
            if (replaying) {
                const Vec3& p = model.held_cycle()[phase].p;
                if (++phase == model.held_cycle().size()) phase = 0;
                return p;
            }
            if (model.running()) model.step_finding_period();
            replaying = model.cycle_held();  // from the next sample on
            return model.state().p;
        }
        // next_position() of `n` samples into `out`; free flight in one
        // loop (an Euler step without contact is the same in step_finding_period).
        void next_positions(Vec3* out, std::size_t n) {
            for (std::size_t i = 0; i < n;) {
                if (started && !replaying && model.running() && model.repeat_period() == 0) {
                    const auto flown = static_cast<std::size_t>(
                        model.free_flight_centres(static_cast<std::int64_t>(n - i), out + i));
                    i += flown;
                    if (flown > 0) continue;
                }
                out[i++] = next_position();
            }
        }
        // The position `ahead` samples after the next one, when replaying.
        const Vec3& replayed(std::size_t ahead) const {
            const std::vector<State>& cycle = model.held_cycle();
            return cycle[(phase + ahead) % cycle.size()].p;
        }
        void skip(std::int64_t samples) {
            const auto period = static_cast<std::int64_t>(model.held_cycle().size());
            phase = static_cast<std::size_t>((static_cast<std::int64_t>(phase) + samples) % period);
        }
        std::int64_t replay_period() const {
            return replaying ? static_cast<std::int64_t>(model.held_cycle().size()) : 0;
        }
        ReferenceModel<D> model;
        std::size_t phase = 0;
        bool started = false, replaying = false;
    };

    explicit LockstepReference(const Scenario& s) {
        if (s.dim == 2) two.emplace(s);
        else three.emplace(s);
    }
    // One of the two: the dimension is picked per call by a branch the
    // predictor always gets right, not by a visit that inlines nothing.
    std::optional<Replaying<2>> two;
    std::optional<Replaying<3>> three;
    template <class F>
    decltype(auto) with(F&& f) {
        return two ? f(*two) : f(*three);
    }
    template <class F>
    decltype(auto) with(F&& f) const {
        return two ? f(*two) : f(*three);
    }
};

// The shared baselines (TrajectoryComparer::share_baselines).
class BaselineTrack {
public:
    std::vector<Vec3> reference, exact;  // at sample n
    // The lockstep reference after the last tracked sample, for a comparer
    // whose stream goes on.
    std::unique_ptr<TrajectoryComparer::LockstepReference> after;
};

std::shared_ptr<const BaselineTrack> TrajectoryComparer::share_baselines(const Scenario& s, const ExactModel& exact,
                                                                         std::int64_t max_samples) {
    auto track = std::make_shared<BaselineTrack>();
    track->after = std::make_unique<LockstepReference>(s);
    DocumentClock clock(s.dt, s.duration);
    // The clock's samples: the first state and every step after it.
    const std::int64_t samples = std::min(max_samples - 1, clock.remaining_steps()) + 1;
    track->reference.resize(static_cast<std::size_t>(samples));
    track->exact.resize(static_cast<std::size_t>(samples));
    track->after->with([&](auto& r) { r.next_positions(track->reference.data(), track->reference.size()); });
    ExactModel::Cursor at(exact);
    for (Vec3& p : track->exact) {
        p = at.state(clock.t()).p;
        clock.advance();
    }
    return track;
}

TrajectoryComparer::TrajectoryComparer(const Scenario& s, const ExactModel& exact,
                                       std::optional<double> reference_rest, std::optional<double> exact_rest,
                                       std::shared_ptr<const BaselineTrack> track)
    : TrajectoryComparer(s, exact, reference_rest, exact_rest, std::move(track), false) {}

TrajectoryComparer TrajectoryComparer::of_the_reference(const Scenario& s, const ExactModel& exact,
                                                        std::optional<double> exact_rest,
                                                        std::shared_ptr<const BaselineTrack> track) {
    return TrajectoryComparer(s, exact, std::nullopt, exact_rest, std::move(track), true);
}

TrajectoryComparer::TrajectoryComparer(const Scenario& s, const ExactModel& exact,
                                       std::optional<double> reference_rest, std::optional<double> exact_rest,
                                       std::shared_ptr<const BaselineTrack> track, bool stream_is_reference)
    : exact_model_(exact),
      exact_(exact),
      track_(std::move(track)),
      tracked_(track_ ? static_cast<std::int64_t>(track_->reference.size()) : 0),
      clock_(s.dt, s.duration),
      dim_(s.dim),
      stream_is_reference_(stream_is_reference),
      reference_(track_ || stream_is_reference ? nullptr : std::make_unique<LockstepReference>(s)),
      vs_reference_(std::make_unique<Stats>(reference_rest)),
      vs_exact_(std::make_unique<Stats>(exact_rest)) {}

TrajectoryComparer::~TrajectoryComparer() = default;

TrajectoryComparer::LockstepReference& TrajectoryComparer::reference() {
    if (!reference_) reference_ = std::make_unique<LockstepReference>(*track_->after);
    return *reference_;
}

void TrajectoryComparer::write(const State& s) { write_block({&s, 1}); }

// On the shared track first; past it, on the comparer's own track, made a
// chunk at a time just before it is read.
void TrajectoryComparer::write_block(std::span<const State> states) {
    if (sample_ < tracked_) {
        const auto on_track =
            static_cast<std::size_t>(std::min<std::int64_t>(tracked_ - sample_, std::ssize(states)));
        const auto n = static_cast<std::size_t>(sample_);
        compare_block<true>(states.first(on_track), track_->reference.data() + n, track_->exact.data() + n);
        states = states.subspan(on_track);
    }
    while (!states.empty()) {
        const std::span<const State> chunk = states.first(std::min(states.size(), kOwnTrack));
        make_own_track(chunk);
        compare_block<false>(chunk, own_reference_.data(), own_exact_.data());
        states = states.subspan(chunk.size());
    }
}

// Past the shared track: the reference stepped on and exact evaluated at
// the stream's times, into arrays, each in its own loop.
void TrajectoryComparer::make_own_track(std::span<const State> states) {
    own_reference_.resize(kOwnTrack);
    own_exact_.resize(kOwnTrack);
    if (!stream_is_reference_)
        reference().with([&](auto& r) { r.next_positions(own_reference_.data(), states.size()); });
    exact_.positions(states, own_exact_.data());
}

namespace {

// |a - b|^2 over the first D axes: in 2D the same bits as over three (the
// unused axis adds an exact +0 to a sum of squares).
template <int D>
double squared_distance(const Vec3& a, const Vec3& b) {
    if constexpr (D == 2) return (a.head<2>() - b.head<2>()).squaredNorm();
    else return (a - b).squaredNorm();
}

}  // namespace

template <bool OnSharedTrack>
void TrajectoryComparer::compare_block(std::span<const State> states, const Vec3* reference, const Vec3* exact) {
    if (dim_ == 2) compare_block<2, OnSharedTrack>(states, reference, exact);
    else compare_block<3, OnSharedTrack>(states, reference, exact);
}

// Sample n against the baselines' sample n, with the running figures in
// locals for the block: as members behind pointers every sample stored and
// reloaded them. On the shared track, exact is read where the stream's
// time is the clock's (an imported stream's may not be). The distances go
// to the plotted series a chunk at a time, in the series' own loop.
template <int D, bool OnSharedTrack>
void TrajectoryComparer::compare_block(std::span<const State> states, const Vec3* reference, const Vec3* exact) {
    Stats to_reference = *vs_reference_, to_exact = *vs_exact_;
    DocumentClock clock = clock_;
    const bool zero_to_reference = stream_is_reference_;
    std::array<double, kOwnTrack> dr, de;  // squared distances
    for (std::size_t begin = 0; begin < states.size(); begin += kOwnTrack) {
        const std::span<const State> chunk = states.subspan(begin, std::min(kOwnTrack, states.size() - begin));
        for (std::size_t i = 0; i < chunk.size(); ++i) {
            const State& s = chunk[i];
            dr[i] = zero_to_reference ? 0.0 : squared_distance<D>(s.p, reference[begin + i]);
            if constexpr (OnSharedTrack) {
                de[i] = s.t == clock.t() ? squared_distance<D>(s.p, exact[begin + i])
                                         : squared_distance<D>(s.p, exact_.state(s.t).p);
                clock.advance();
            } else {
                de[i] = squared_distance<D>(s.p, exact[begin + i]);
            }
            to_reference.add(s.t, dr[i]);
            to_exact.add(s.t, de[i]);
        }
        if (reference_series_) {
            reference_series_->add(chunk, dr.data());
            exact_series_->add(chunk, de.data());
        }
    }
    sample_ += std::ssize(states);
    clock_ = clock;
    *vs_reference_ = to_reference;
    *vs_exact_ = to_exact;
}

void TrajectoryComparer::write_states(PeriodicTail::Cursor& at, std::int64_t count) {
    std::array<State, kOwnTrack> block;
    while (count > 0) {
        const auto n = static_cast<std::size_t>(std::min<std::int64_t>(count, std::ssize(block)));
        for (std::size_t i = 0; i < n; ++i) block[i] = at.next();
        write_block(std::span<const State>(block.data(), n));
        count -= static_cast<std::int64_t>(n);
    }
}

void TrajectoryComparer::write_periodic(const PeriodicTail& tail) {
    const std::int64_t period = tail.period();
    PeriodicTail::Cursor at(tail);
    // The common period of the tail and the reference's cycle, if both
    // baselines repeat from the next sample on and it is not too long.
    auto common_period = [&]() -> std::int64_t {
        const std::int64_t reference_period =
            stream_is_reference_ ? period : reference().with([](auto& r) { return r.replay_period(); });
        if (reference_period == 0 || !exact_model_.still_after(at.next_t())) return 0;
        const std::int64_t common = std::lcm(period, reference_period);
        return common <= kMaxReplayedPeriod ? common : 0;
    };
    write_states(at, std::min(at.left(), std::max<std::int64_t>(tracked_ - sample_, 0)));
    if (at.left() == 0) return;
    std::int64_t common = 0;
    while (at.left() > 0 && (common = common_period()) == 0) write(at.next());
    if (at.left() == 0) return;
    const Vec3 exact_p = exact_model_.state_at(at.next_t()).p;  // still: the same at every later sample
    std::vector<double> to_reference(common), to_exact(common);
    for (std::int64_t j = 0; j < common; ++j) {
        const Vec3& p = tail.cycle[(at.phase() + j) % period].p;
        to_reference[j] =
            stream_is_reference_ ? 0.0 : reference().with([&](auto& r) { return (p - r.replayed(j)).squaredNorm(); });
        to_exact[j] = (p - exact_p).squaredNorm();
    }
    if (!stream_is_reference_) reference().with([&](auto& r) { r.skip(at.left()); });
    sample_ += at.left();
    vs_reference_->add_periodic(at, to_reference);
    vs_exact_->add_periodic(at, to_exact);
    if (reference_series_) {
        reference_series_->add_periodic(at, to_reference);
        exact_series_->add_periodic(at, to_exact);
    }
}

void TrajectoryComparer::record_series(std::int64_t stride) {
    reference_series_.emplace(stride);
    exact_series_.emplace(stride);
}

namespace {

std::optional<DistanceSeries> rooted(const std::optional<WindowMaxSeries>& squared) {
    if (!squared) return std::nullopt;
    DistanceSeries out{squared->times(), squared->values()};
    // Two roots an instruction (correctly rounded, as std::sqrt): one at a
    // time they were a twentieth of a short run's harness.
    Eigen::Map<Eigen::ArrayXd> distance(out.distance.data(), std::ssize(out.distance));
    distance = distance.sqrt();
    return out;
}

}  // namespace

std::optional<DistanceSeries> TrajectoryComparer::reference_series() const { return rooted(reference_series_); }
std::optional<DistanceSeries> TrajectoryComparer::exact_series() const { return rooted(exact_series_); }
TrajectoryDivergence TrajectoryComparer::vs_reference() const { return vs_reference_->finished(); }
TrajectoryDivergence TrajectoryComparer::vs_exact() const { return vs_exact_->finished(); }

std::vector<ContactEvent> floor_contacts(const SimulatorSummary& r, int vertical) {
    std::vector<ContactEvent> out;
    for (const ContactEvent& c : r.contact_events)
        if (c.axis == vertical && c.side < 0) out.push_back(c);
    return out;
}

namespace {

// The first floor contact after time t.
std::optional<double> contact_after(const std::vector<ContactEvent>& floor, double t) {
    for (const ContactEvent& c : floor)
        if (c.t > t) return c.t;
    return std::nullopt;
}

}  // namespace

Divergence compare_bounces(const SimulatorSummary& self, const SimulatorSummary& baseline, int bounce_count,
                           const Scenario& s) {
    Divergence d;
    d.baseline = baseline.simulator;
    d.apexes_self = self.apex_count;
    d.apexes_baseline = baseline.apex_count;
    const int vertical = s.vertical_axis();
    const auto self_floor = floor_contacts(self, vertical), base_floor = floor_contacts(baseline, vertical);
    const std::size_t available = std::min(self.apexes.size(), baseline.apexes.size());
    const std::size_t n = std::min(available, static_cast<std::size_t>(std::max(bounce_count, 0)));
    for (std::size_t i = 0; i < n; ++i) {
        BounceDiff b;
        b.index = static_cast<int>(i);
        b.height = self.apexes[i].height;
        b.baseline_height = baseline.apexes[i].height;
        b.abs_diff = std::abs(b.height - b.baseline_height);
        // Relative to the bounce's height above the floor, where the ball's centre rests.
        const double above_floor = std::abs(b.baseline_height - s.radius);
        b.rel_diff = above_floor > 0 ? b.abs_diff / above_floor : 0.0;
        b.contact_t = contact_after(self_floor, self.apexes[i].t);
        b.baseline_contact_t = contact_after(base_floor, baseline.apexes[i].t);
        d.bounce_height_rel_max = std::max(d.bounce_height_rel_max, b.rel_diff);
        if (b.contact_t && b.baseline_contact_t)
            d.contact_time_max = std::max(d.contact_time_max.value_or(0.0), std::abs(*b.contact_t - *b.baseline_contact_t));
        d.bounces.push_back(b);
    }
    if (n < static_cast<std::size_t>(bounce_count)) {
        d.note = fmt::format("compared {} of the {} bounces asked: {} has {} apexes, {} has {}", n, bounce_count,
                             self.simulator, self.apexes.size(), baseline.simulator, baseline.apexes.size());
    } else if (self.apex_count != baseline.apex_count) {
        d.note = fmt::format("compared the first {} bounces; the runs have {} and {} apexes", n, self.apex_count,
                             baseline.apex_count);
    }
    return d;
}

}  // namespace bouncecheck
