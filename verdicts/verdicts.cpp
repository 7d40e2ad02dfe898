#include "verdicts/verdicts.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>

namespace bouncecheck {

bool Comparison::passed() const {
    for (const ThresholdCheck& t : thresholds)
        if (!t.passed) return false;
    return true;
}

double min_measured_impact_speed(const Scenario& s) {
    return kMinSpeedInSteps * s.gravity.norm() * s.dt;
}

std::vector<ContactEvent> damping_contacts(const SimulatorSummary& self, const Scenario& s) {
    const double min_speed = min_measured_impact_speed(s);
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
    d.tangential_loss_tolerance = limits.tangential_loss_rel.value_or(kDefaultTangentialLossTolerance);
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
    if (d.tangential_contacts > 0) {
        d.tangential_mean = tangential_sum / d.tangential_contacts;
        // The law's loss is small (1%): judged on its own scale, a worst
        // retention within 0.02 of beta would pass no loss at all.
        d.tangential_loss_mean = 1 - d.tangential_mean;
        d.tangential_loss_rel =
            std::abs(d.tangential_loss_mean - (1 - s.beta)) / std::max(1 - s.beta, kMinTangentialLossScale);
    }
    std::vector<std::string> differs;
    if (d.contacts == 0) differs.push_back("no contact to measure");
    if (normal_dev > d.normal_tolerance)
        differs.push_back(fmt::format("normal coefficient up to {:.4f} against alpha {:g} (tolerance {:g})",
                                      d.normal_worst, s.alpha, d.normal_tolerance));
    if (tangential_dev > d.tangential_tolerance)
        differs.push_back(fmt::format("tangential retention up to {:.4f} against beta {:g} (tolerance {:g})",
                                      d.tangential_worst, s.beta, d.tangential_tolerance));
    if (d.tangential_contacts > 0 && d.tangential_loss_rel > d.tangential_loss_tolerance)
        differs.push_back(fmt::format("tangential loss {:.4f} a contact on average against the law's {:.4f} "
                                      "({:.0f}% off, tolerance {:g}%)",
                                      d.tangential_loss_mean + 0.0, 1 - s.beta, 100 * d.tangential_loss_rel,
                                      100 * d.tangential_loss_tolerance));
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
    check("tangential_loss_rel", limits.tangential_loss_rel,
          c.damping.tangential_contacts > 0 ? c.damping.tangential_loss_rel : none);
    // Against exact: the same figures as against the reference, and the
    // floor contacts' times, which rank engines where the trajectory's
    // distance is dominated by one shifted event.
    const Divergence& truth = c.vs_exact;
    check("error_bounce_height_rel", limits.error_bounce_height_rel, truth.bounce_height_rel_max);
    // With no contact compared, a limit on its time fails.
    check("error_contact_time", limits.error_contact_time, truth.contact_time_max.value_or(none));
    check("error_trajectory_rms", limits.error_trajectory_rms, truth.trajectory.rms_before_rest);
    check("error_trajectory_max", limits.error_trajectory_max, truth.trajectory.max_before_rest);
    return out;
}

ThresholdSet limits_for(const Scenario& s, const std::string& simulator, const ThresholdSet& overrides) {
    if (simulator == "reference") {
        const auto it = s.thresholds.simulator.find("reference");
        const ThresholdSet own = it == s.thresholds.simulator.end() ? ThresholdSet{} : it->second;
        return own.overridden_by(overrides);
    }
    return s.thresholds.for_simulator(simulator).overridden_by(overrides);
}

}  // namespace bouncecheck
