#include "compare/comparison.h"

#include "reference/reference_model.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <variant>

namespace bouncecheck {

bool Comparison::passed() const {
    for (const ThresholdCheck& t : thresholds)
        if (!t.passed) return false;
    return true;
}

// Running distance statistics against one baseline.
struct TrajectoryComparer::Stats {
    explicit Stats(std::optional<double> rest) { result.rest_cut = rest; }
    void add(double t, double distance) {
        sum_sq += distance * distance;
        ++result.samples;
        result.max = std::max(result.max, distance);
        if (!result.rest_cut || t < *result.rest_cut) {
            sum_sq_before += distance * distance;
            ++samples_before;
            result.max_before_rest = std::max(result.max_before_rest, distance);
        }
        if (!result.first_exceeds && distance > result.tolerance) result.first_exceeds = t;
    }
    TrajectoryDivergence finished() const {
        TrajectoryDivergence out = result;
        if (out.samples > 0) out.rms = std::sqrt(sum_sq / static_cast<double>(out.samples));
        if (samples_before > 0) out.rms_before_rest = std::sqrt(sum_sq_before / static_cast<double>(samples_before));
        return out;
    }
    TrajectoryDivergence result;
    double sum_sq = 0, sum_sq_before = 0;
    std::int64_t samples_before = 0;
};

// The reference stepped in lockstep with the compared stream: its sample n is
// at the same document-clock time as the stream's sample n.
struct TrajectoryComparer::LockstepReference {
    explicit LockstepReference(const Scenario& s) {
        if (s.dim == 2) model.emplace<ReferenceModel<2>>(s);
        else model.emplace<ReferenceModel<3>>(s);
    }
    State next(bool first) {
        return std::visit(
            [&](auto& m) -> State {
                if constexpr (std::is_same_v<std::decay_t<decltype(m)>, std::monostate>) {
                    return State{};
                } else {
                    if (!first && m.running()) m.step();
                    return m.state();
                }
            },
            model);
    }
    std::variant<std::monostate, ReferenceModel<2>, ReferenceModel<3>> model;
    bool started = false;
};

TrajectoryComparer::TrajectoryComparer(const Scenario& s, const ExactModel& exact,
                                       std::optional<double> reference_rest, std::optional<double> exact_rest)
    : exact_(exact),
      reference_(std::make_unique<LockstepReference>(s)),
      vs_reference_(std::make_unique<Stats>(reference_rest)),
      vs_exact_(std::make_unique<Stats>(exact_rest)) {}

TrajectoryComparer::~TrajectoryComparer() = default;

void TrajectoryComparer::write(const State& s) {
    const State ref = reference_->next(!reference_->started);
    reference_->started = true;
    const double to_reference = (s.p - ref.p).norm();
    const double to_exact = (s.p - exact_.state_at(s.t).p).norm();
    vs_reference_->add(s.t, to_reference);
    vs_exact_->add(s.t, to_exact);
    if (reference_series_) {
        reference_series_->add(s.t, to_reference);
        exact_series_->add(s.t, to_exact);
    }
}

void TrajectoryComparer::record_series(std::int64_t stride) {
    reference_series_.emplace(stride);
    exact_series_.emplace(stride);
}

TrajectoryDivergence TrajectoryComparer::vs_reference() const { return vs_reference_->finished(); }
TrajectoryDivergence TrajectoryComparer::vs_exact() const { return vs_exact_->finished(); }

namespace {

// Floor contacts in time order.
std::vector<ContactEvent> floor_contacts(const SimulatorSummary& r, int vertical) {
    std::vector<ContactEvent> out;
    for (const ContactEvent& c : r.contact_events)
        if (c.axis == vertical && c.side < 0) out.push_back(c);
    return out;
}

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

std::vector<ContactEvent> damping_contacts(const SimulatorSummary& self, const Scenario& s) {
    // Measured from samples a step apart, a contact's coefficients carry one
    // step of gravity, |g| dt, against its incoming speed: contacts slower than
    // kMinSpeedInSteps |g| dt (micro-bounces) would measure gravity, not damping.
    const double min_speed = kMinSpeedInSteps * s.gravity.norm() * s.dt;
    std::vector<ContactEvent> out;
    for (const ContactEvent& c : self.contact_events) {
        if (self.rest_time && c.t >= *self.rest_time) break;
        if (c.normal_speed_in >= min_speed) out.push_back(c);
    }
    return out;
}

DampingCheck check_damping(const SimulatorSummary& self, const Scenario& s, const ThresholdSet& limits) {
    DampingCheck d;
    d.normal_tolerance = limits.restitution_abs.value_or(kDefaultDampingTolerance);
    d.tangential_tolerance = limits.tangential_abs.value_or(kDefaultDampingTolerance);
    double normal_sum = 0, tangential_sum = 0, normal_dev = -1, tangential_dev = -1;
    for (const ContactEvent& c : damping_contacts(self, s)) {
        ++d.contacts;
        normal_sum += c.normal_coefficient;
        if (std::abs(c.normal_coefficient - s.alpha) > normal_dev) {
            normal_dev = std::abs(c.normal_coefficient - s.alpha);
            d.normal_worst = c.normal_coefficient;
        }
        if (std::isnan(c.tangential_retention)) continue;
        ++d.tangential_contacts;
        tangential_sum += c.tangential_retention;
        if (std::abs(c.tangential_retention - s.beta) > tangential_dev) {
            tangential_dev = std::abs(c.tangential_retention - s.beta);
            d.tangential_worst = c.tangential_retention;
        }
    }
    if (d.contacts > 0) d.normal_mean = normal_sum / d.contacts;
    if (d.tangential_contacts > 0) d.tangential_mean = tangential_sum / d.tangential_contacts;
    std::vector<std::string> differs;
    if (d.contacts == 0) differs.push_back("no contact to measure");
    if (normal_dev > d.normal_tolerance)
        differs.push_back(fmt::format("normal coefficient up to {:.4f} against alpha {:g} (tolerance {:g})",
                                      d.normal_worst, s.alpha, d.normal_tolerance));
    if (tangential_dev > d.tangential_tolerance)
        differs.push_back(fmt::format("tangential retention up to {:.4f} against beta {:g} (tolerance {:g})",
                                      d.tangential_worst, s.beta, d.tangential_tolerance));
    d.reproduces = differs.empty();
    d.verdict = d.reproduces ? "reproduces the damping law" : fmt::format("{}", fmt::join(differs, "; "));
    return d;
}

std::vector<ThresholdCheck> check_thresholds(const Comparison& c, const ThresholdSet& limits, const Scenario& s) {
    std::vector<ThresholdCheck> out;
    auto check = [&](const char* metric, const std::optional<double>& limit, double measured) {
        if (limit) out.push_back({metric, measured, *limit, measured <= *limit});
    };
    const Divergence& ref = c.vs_reference;
    check("bounce_height_rel", limits.bounce_height_rel, ref.bounce_height_rel_max);
    if (limits.bounce_count && static_cast<int>(ref.bounces.size()) < *limits.bounce_count) {
        // Fewer bounces than asked: the comparison itself fails, it is not skipped.
        out.push_back({"bounce_count", static_cast<double>(ref.bounces.size()),
                       static_cast<double>(*limits.bounce_count), false});
    }
    check("trajectory_rms", limits.trajectory_rms, ref.trajectory.rms);
    check("trajectory_max", limits.trajectory_max, ref.trajectory.max);
    // With nothing measured, a damping limit fails rather than passing unseen.
    const double none = std::numeric_limits<double>::infinity();
    check("restitution_abs", limits.restitution_abs,
          c.damping.contacts > 0 ? std::abs(c.damping.normal_worst - s.alpha) : none);
    check("tangential_abs", limits.tangential_abs,
          c.damping.tangential_contacts > 0 ? std::abs(c.damping.tangential_worst - s.beta) : none);
    return out;
}

}  // namespace bouncecheck
