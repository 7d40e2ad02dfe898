// What one simulator's run of one scenario produced, and the streaming
// recorder that computes it from the simulator's states as they are made.
#pragma once

#include "adapters/state.h"
#include "scenarios/scenario.h"

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace bouncecheck {

enum class RunStatus { ok, skipped, failed };
const char* to_string(RunStatus s);

struct SimulatorSummary {
    std::string simulator;
    RunStatus status = RunStatus::ok;
    std::string reason;  // why it was skipped or failed

    std::int64_t steps = 0;           // steps taken (exact: samples after the initial one)
    std::int64_t contacts = 0;        // wall contacts; a corner counts one per wall
    std::int64_t floor_contacts = 0;
    bool contacts_unbounded = false;  // exact: infinitely many Zeno contacts summed in closed form
    std::vector<Apex> apexes;         // the first kReportedApexes apexes
    // The first kReportedApexes floor contacts: time and measured restitution,
    // |outgoing| / |incoming| normal speed (stepped simulators: from the
    // samples just before and after the contact; exact: at the instant).
    struct FloorContact {
        double t = 0;
        double restitution = 0;
    };
    std::vector<FloorContact> first_floor_contacts;
    std::int64_t apex_count = 0;
    // Vertical motion at rest on the floor from this time. exact: the Zeno
    // accumulation time. Stepped simulators: from the stream (see StreamRecorder).
    std::optional<double> rest_time;
    State final_state;
    // Every setting that changes the answer, as used (engine version,
    // precision, restitution and friction and their combine rules, thresholds,
    // slop, sleeping, scale...): key, value, and why it was chosen.
    struct Setting {
        std::string key, value, why;
    };
    std::vector<Setting> settings;
    double run_seconds = 0;  // wall time of the run, recording included
    std::string trajectory_file;  // relative to the output folder, if written
};

inline constexpr std::size_t kReportedApexes = 5;

// Consumes a simulator's state stream: counts contacts, finds apexes (the
// highest sample between floor contacts), watches for non-finite states and
// for a ball beyond the room's walls, and passes every state to a sink if given.
class StreamRecorder {
public:
    StreamRecorder(const Scenario& s, StateSink* sink);

    void on_state(const State& s, ContactMask contact) {
        if (sink_) sink_->write(s);
        check(s);
        if (contact.any()) count_contacts(s, contact);
        track_rest(s);
        const double height = s.p[vertical_];
        if (!apex_open_ || height > apex_.height) {
            apex_ = Apex{s.t, height};
            apex_open_ = true;
        }
        last_ = s;
        ++states_;
    }

    bool failed() const { return !failure_.empty(); }
    // Fills counts, apexes, status and final state; the caller adds timing.
    void finish(SimulatorSummary& out);

private:
    void check(const State& s);
    void count_contacts(const State& s, ContactMask contact);
    void push_apex(const Apex& a);
    void track_rest(const State& s) {
        const bool resting = s.p[vertical_] - floor_ <= rest_height_ && std::abs(s.v[vertical_]) <= rest_speed_;
        if (!resting) rest_since_.reset();
        else if (!rest_since_) rest_since_ = s.t;
    }

    StateSink* sink_;
    int dim_;
    int vertical_;
    Vec3 low_limit_, high_limit_;  // centre positions beyond which the ball has left the room
    std::int64_t states_ = 0, contacts_ = 0, floor_contacts_ = 0, apex_count_ = 0;
    std::vector<Apex> apexes_;
    std::vector<SimulatorSummary::FloorContact> floor_contacts_seen_;
    Apex apex_;
    bool apex_open_ = false;
    State last_;
    std::string failure_;
    // Vertical rest: from rest_since_ on, the ball stayed within rest_height_
    // of the floor with vertical speed below rest_speed_ (see summary.cpp).
    static constexpr int kRestSteps = 10;
    double floor_, rest_height_, rest_speed_, dt_;
    std::optional<double> rest_since_;
};

}  // namespace bouncecheck
