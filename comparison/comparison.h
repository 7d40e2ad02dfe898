// How far a simulator is from the reference (divergence) and from exact
// (error): bounce by bounce, and sample by sample over the trajectory.
//
// Every simulator of a run samples on the document's clock (the scenario's
// dt), so sample n of one is at the time of sample n of any other: the
// trajectory comparison is sample by sample, with no interpolation.
#pragma once

#include "comparison/window_max_series.h"
#include "exact/exact_model.h"
#include "metrics/summary.h"
#include "scenarios/scenario.h"
#include "simulators/document_clock.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace bouncecheck {

inline constexpr double kDivergenceTolerance = 0.01;  // m: "first exceeds" time of the trajectory

// One bounce (apex index) against the baseline's.
struct BounceDiff {
    int index = 0;
    double height = 0, baseline_height = 0;
    double abs_diff = 0, rel_diff = 0;  // rel: abs_diff / baseline height above the floor
    std::optional<double> contact_t, baseline_contact_t;  // the floor contact that ends this bounce
};

struct TrajectoryDivergence {
    std::int64_t samples = 0;
    double rms = 0, max = 0;                          // over the whole run
    std::optional<double> rest_cut;                   // the baseline's rest time, if it rests
    double rms_before_rest = 0, max_before_rest = 0;  // over [0, rest_cut) (the whole run without one)
    double tolerance = kDivergenceTolerance;
    std::optional<double> first_exceeds;              // first time the distance exceeded `tolerance`
};

// A simulator against one baseline (reference or exact).
struct Divergence {
    std::string baseline;
    std::vector<BounceDiff> bounces;  // min(bounce_count, both sides' apex counts)
    double bounce_height_rel_max = 0;
    // The largest |floor-contact time - the baseline's| over the compared
    // bounces (s); empty when no bounce has both. With the bounce heights it
    // ranks engines where one shifted event dominates the trajectory's distance.
    std::optional<double> contact_time_max;
    std::int64_t apexes_self = 0, apexes_baseline = 0;
    std::string note;  // how sequences of different lengths were handled
    TrajectoryDivergence trajectory;
};

// A run's floor contacts (the lower wall of `vertical`), in time order.
std::vector<ContactEvent> floor_contacts(const SimulatorSummary& r, int vertical);

// A distance over time as report.html plots it: the largest of each window
// of samples, with its time (WindowMaxSeries).
struct DistanceSeries {
    std::vector<double> t, distance;
};

class BaselineTrack;

// Compares a simulator's state stream, as it streams, with the reference
// and with exact (read from the shared track, then the reference stepped
// alongside and exact evaluated). Pass it as the run's StateSink.
class TrajectoryComparer final : public StateSink {
public:
    // With a track (share_baselines), the baselines' first samples are read
    // from it rather than made again: the same results, bit for bit.
    TrajectoryComparer(const Scenario& s, const ExactModel& exact, std::optional<double> reference_rest,
                       std::optional<double> exact_rest, std::shared_ptr<const BaselineTrack> track = nullptr);
    // For the reference's own stream: its distance to the reference is
    // zero at every sample, so no second reference is stepped beside it.
    // vs_reference() then has no rest cut: the caller knows the stream's rest
    // only once it has run (a zero distance gives the same figures with any cut).
    static TrajectoryComparer of_the_reference(const Scenario& s, const ExactModel& exact,
                                               std::optional<double> exact_rest,
                                               std::shared_ptr<const BaselineTrack> track = nullptr);
    ~TrajectoryComparer() override;

    // The reference's positions at the document clock's first samples and
    // exact's at their times, made once per scenario for every simulator's
    // comparer to read: each would otherwise step the reference and
    // evaluate exact itself, the larger part of what comparing costs
    // (bench/README.md, 6). At most `max_samples` (48 bytes each), so the
    // memory stays flat in the run's length; past them a comparer steps on
    // from where the track ends.
    static constexpr std::int64_t kSharedSamples = 1 << 17;
    static std::shared_ptr<const BaselineTrack> share_baselines(const Scenario& s, const ExactModel& exact,
                                                                std::int64_t max_samples = kSharedSamples);
    // A block of one.
    void write(const State& s) override;
    // Each state of the block against the baselines' sample of the same
    // index, in one loop per stretch of baselines (the shared track, then
    // the comparer's own).
    void write_block(std::span<const State> states) override;
    // State by state until both baselines repeat as well (the reference at
    // its rest cycle, exact still); from there the distances repeat with the
    // cycles' common period and are added up without evaluating anything.
    // Same results as writing each state, bit for bit.
    void write_periodic(const PeriodicTail& tail) override;
    TrajectoryDivergence vs_reference() const;
    TrajectoryDivergence vs_exact() const;
    // Also keeps both distances over time, for the HTML report: the largest of
    // every `stride` samples (see WindowMaxSeries).
    void record_series(std::int64_t stride);
    // Empty unless record_series was called.
    std::optional<DistanceSeries> reference_series() const;
    std::optional<DistanceSeries> exact_series() const;

private:
    friend class BaselineTrack;
    TrajectoryComparer(const Scenario& s, const ExactModel& exact, std::optional<double> reference_rest,
                       std::optional<double> exact_rest, std::shared_ptr<const BaselineTrack> track,
                       bool stream_is_reference);
    struct Stats;
    struct LockstepReference;
    // Compares a block with the baselines' positions at its samples (see write_block).
    template <bool OnSharedTrack>
    void compare_block(std::span<const State> states, const Vec3* reference, const Vec3* exact);
    template <int D, bool OnSharedTrack>
    void compare_block(std::span<const State> states, const Vec3* reference, const Vec3* exact);
    static constexpr std::size_t kOwnTrack = 256;  // samples made at a time past the shared track
    void make_own_track(std::span<const State> states);
    // The cursor's next `count` states, written in blocks.
    void write_states(PeriodicTail::Cursor& at, std::int64_t count);
    // Past the track: the reference as it stands after the track's samples.
    LockstepReference& reference();
    const ExactModel& exact_model_;
    ExactModel::Cursor exact_;  // the stream's times do not decrease
    std::shared_ptr<const BaselineTrack> track_;
    std::int64_t tracked_ = 0, sample_ = 0;  // the track's samples; the next sample's index
    DocumentClock clock_;                    // the next sample's time on the document clock
    int dim_;
    bool stream_is_reference_ = false;              // of_the_reference
    std::unique_ptr<LockstepReference> reference_;  // made when first needed past the track
    std::unique_ptr<Stats> vs_reference_, vs_exact_;
    std::optional<WindowMaxSeries> reference_series_, exact_series_;  // of squared distances
    std::vector<Vec3> own_reference_, own_exact_;  // past the shared track: the current chunk's
};

// Bounce-by-bounce comparison of two summaries' apexes and floor contacts.
Divergence compare_bounces(const SimulatorSummary& self, const SimulatorSummary& baseline, int bounce_count,
                           const Scenario& s);

}  // namespace bouncecheck
