// What one simulator's run of one scenario produced, and the streaming
// recorder that computes it from the simulator's states as they are made.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/simulator.h"
#include "simulators/state.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bouncecheck {

// One wall contact with its measured damping (see measure_contact).
struct ContactEvent {
    double t = 0;
    int axis = 0;
    int side = -1;                    // -1 lower wall, +1 upper wall
    double normal_coefficient = 0;    // |v_n after| / |v_n before|: alpha in the model
    double tangential_retention = 0;  // |v_t after| / |v_t before|: beta in the model; NaN if undefined
    double normal_speed_in = 0;       // |v_n before|
};

struct SimulatorSummary {
    std::string simulator;
    std::string origin;  // Simulator::origin(): empty for a built simulator
    RunStatus status = RunStatus::ok;
    std::string reason;  // why it was skipped or failed

    std::int64_t steps = 0;           // steps taken (exact: samples after the initial one)
    std::int64_t contacts = 0;        // wall contacts; a corner counts one per wall
    std::int64_t floor_contacts = 0;
    bool contacts_unbounded = false;  // exact: infinitely many Zeno contacts summed in closed form
    std::vector<Apex> apexes;         // the first kKeptApexes apexes
    std::int64_t apex_count = 0;
    // The first kKeptContacts contacts with their measured damping.
    std::vector<ContactEvent> contact_events;
    double max_penetration = 0;    // deepest the ball's surface went beyond a wall (m)
    double energy_max_rise = 0;    // largest rise of 0.5|v|^2 - g.p above its initial value (J/kg)
    // Vertical motion at rest on the floor from this time. exact: the Zeno
    // accumulation time. Stepped simulators: from the stream (see StreamRecorder).
    std::optional<double> rest_time;
    State final_state;
    std::vector<Setting> settings;  // as the simulator used them (RunOutcome)
    // From this time on the run's states were periodic and handed over, not
    // stepped (PeriodicTail): the period in steps (1: a state at rest) and
    // how many of the run's steps that was.
    std::optional<double> filled_from;
    std::int64_t fill_period = 0, fill_steps = 0;
    double run_seconds = 0;  // wall time of the run, recording included; NaN: not reported (--no-timings)
    // The engine's own steps, where the simulator timed them (RunOutcome);
    // the cost per step is then this over the steps, and the rest of
    // run_seconds (start-up, streaming) is reported apart.
    std::optional<double> step_seconds;
    // What one step cost (ns): step_seconds, else run_seconds, over the steps; NaN without either.
    double ns_per_step() const;
    std::string trajectory_file;  // relative to the output folder, if written
};

inline constexpr std::size_t kKeptApexes = 64;
inline constexpr std::size_t kKeptContacts = 4096;
inline constexpr std::size_t kReportedApexes = 5;  // in the terminal summary

// A contact's damping as measured: |outgoing| / |incoming| normal speed, and
// |outgoing| / |incoming| tangential speed (NaN when the incoming tangential
// speed is below 1e-9 m/s), both velocities at the impact instant.
// exact: its own instant. Stepped simulators: see impact_velocities.
// `normal_axes`: the axes of every wall touched in the same step (bit per
// axis; a corner touches two or three): none of them is tangential, since
// the law reverses each one's component by alpha.
ContactEvent measure_contact(double t, int axis, int side, const Vec3& v_before, const Vec3& v_after, int dim,
                             unsigned normal_axes = 0);

// The velocities just before and just after an impact that happened in the
// step from `before` to `after` (samples of a stepped simulator), on the
// wall of `axis`/`side` whose centre plane is `wall`. The impact instant is
// where the flight after the contact, traced back from `after` under
// gravity, meets that plane within the step (the step's start if it does
// not reach it; `after` itself if that lies on or beyond the plane). The
// incoming velocity is the flight before, from `before`, at that instant;
// the outgoing one the flight after at it. So the reference (its sample
// after a contact lies on the wall) measures alpha and beta exactly, an
// event-driven simulator whose impact falls between samples does too (to
// round-off), and an engine that bounces the velocity from the start of the
// step measures its restitution at the step's start.
struct ImpactVelocities {
    double t;  // the impact instant
    Vec3 incoming, outgoing;
};
ImpactVelocities impact_velocities(const State& before, const State& after, int axis, int side, double wall,
                                   const Vec3& gravity);

// Where the ball's centre touches the walls: per axis r (lower) and size - r
// (upper); unused axes (z in 2D) are unbounded. Every per-state measure runs
// over the first D axes with these, a loop the compiler unrolls: D = 3 is
// always right (an unused axis is unbounded and its state zero, so it changes
// no bit), D = 2 skips that axis's work in a 2D scene.
struct WallLimits {
    explicit WallLimits(const Scenario& s);
    Vec3 low, high;
    // How far the ball's surface reaches beyond the nearest wall it overlaps
    // (m): the largest of r - p_i and p_i - (size_i - r); <= 0 while clear.
    template <int D = 3>
    double penetration(const Vec3& p) const {
        double deepest = -std::numeric_limits<double>::infinity();
        for (int i = 0; i < D; ++i) deepest = std::max(deepest, std::max(low[i] - p[i], p[i] - high[i]));
        return deepest;
    }
};
// Mechanical energy per unit mass (J/kg): 0.5 |v|^2 - g.p (the unused axis
// has g = p = 0 and subtracts an exact zero). A component below 2^-538
// squares to +0 (under half the least subnormal): it is squared as 0, the
// same bits without the processor's slow path for a subnormal or
// underflowing product (a ball at rest keeps subnormal tangential
// velocities for about 1e5 states; that square was 40% of the recorder).
template <int D = 3>
double specific_energy(const State& s, const Vec3& gravity) {
    // Summed in registers, in the order of s.v.squaredNorm() (the test
    // holds them to the bit): a copy of v thresholded in memory and read back
    // as a pair stalled on store forwarding, a third of the recorder's time.
    double squared = 0;
    for (int i = 0; i < D; ++i) {
        const double c = std::abs(s.v[i]) < 0x1p-538 ? 0.0 : s.v[i];
        squared += c * c;
    }
    double energy = 0.5 * squared;
    for (int i = 0; i < D; ++i) energy -= gravity[i] * s.p[i];
    return energy;
}

// Consumes a simulator's state stream: counts and measures contacts, finds
// apexes (the highest sample between floor contacts, refined by the parabola
// through it and its neighbours), tracks penetration, energy and rest, watches
// for non-finite states and for a ball beyond the room's walls (and stops the
// run there), and passes every state to a sink if given.
class StreamRecorder final : public RunSink {
public:
    StreamRecorder(const Scenario& s, StateSink* sink);

    // States are recorded in blocks: the simulator makes kBlock states
    // undisturbed, then the recorder and its sink take them one after
    // another while their own code and data are hot. Interleaved state by
    // state, the two evicted each other's caches and branch history, which
    // cost more than the recording itself (bench/README.md, 6). A state
    // that may end the run is recorded at once.
    bool on_state(const State& s, ContactMask contact) override {
        pending_states_[pending_size_] = s;
        pending_contacts_[pending_size_] = contact;
        const bool sound = dim_ == 2 ? plainly_sound<2>(s) : plainly_sound<3>(s);
        if (++pending_size_ == kBlock || !sound) record_pending();  // which diagnoses it
        return !failed();
    }

    // The run's remaining states, periodic: passed to the sink as a tail, and
    // recorded with what stepping on would give, bit for bit (counts, kept
    // contacts and apexes, maxima, rest, final state), without recording each
    // state: whole cycles in the middle are counted, not replayed.
    void on_periodic_tail(const PeriodicTail& tail) override;

    // Contacts, apexes and rest as the simulator resolved them: they replace
    // what the samples showed (exact's contacts at their instants).
    void on_resolved_events(const ResolvedEvents& events) override;

    bool failed() const { return !failure_.empty(); }
    // Records the states taken but not yet recorded. finish() does it; a
    // caller whose simulator threw calls it to keep the states made before.
    void record_pending();
    // Fills counts, apexes, status and final state; the caller adds timing.
    void finish(SimulatorSummary& out);

private:
    static constexpr std::size_t kBlock = 256;  // 16 KB of states: within the first-level cache
    // Finite and inside the room: only a state that is not can fail the
    // run (diagnose), so the blocks stop a run where single states did,
    // and such a state is always the last of its block. D: the axes the
    // recorder looks at (see track).
    template <int D>
    bool plainly_sound(const State& s) const {
        constexpr double largest = std::numeric_limits<double>::max();
        bool sound = true;
        for (int i = 0; i < D; ++i)
            sound &= (s.p[i] >= low_limit_[i]) & (s.p[i] <= high_limit_[i]) & (std::abs(s.v[i]) <= largest);
        return sound;
    }
    // What every state updates. record_pending keeps a copy in locals over
    // a block (as members, each sample stored and reloaded them); the
    // out-of-line calls on contacts take values, not the copy.
    struct Tracking {
        std::int64_t states = 0;
        double energy0 = 0, energy_max_rise = 0, max_penetration = 0;
        Apex apex;
        double apex_before = 0, apex_after = 0;  // heights of the samples around the apex sample
        bool apex_open = false;
        std::optional<double> rest_since;
        State before_previous;         // the state before `previous` (once states > 1)
        ContactMask previous_contact;  // the walls whose contacts were counted at `previous`
    };
    // One state's metrics into `r` (tracking_, or record_pending's copy of
    // it), after `previous` (the stream's state before it;
    // unused for the first). The sink has had it (record_pending passes it
    // the whole block first). D: the axes to look at (see WallLimits); 2 only
    // for a 2D scenario (3 gives the same bits).
    template <int D>
    void track(Tracking& r, const State& previous, const State& s, ContactMask contact) {
        track_energy_and_penetration<D>(r, s);
        if (!stopped_impacts_.empty()) measure_release(previous, s);
        if (contact.any()) {
            count_contacts(previous, s, contact, r.states > 0, r.states > 1 ? &r.before_previous : nullptr,
                           r.previous_contact);
            // A floor contact closes the interval since the previous one: its
            // highest sample is an apex unless the ball never rose above the
            // floor sample.
            if ((contact.lower >> vertical_) & 1u) {
                if (r.apex_open && r.apex.t < s.t) push_apex(r.apex, r.apex_before, r.apex_after);
                r.apex_open = false;
            }
        }
        track_rest(r, s);
        track_apex(r, previous, s);
        r.before_previous = previous;
        r.previous_contact = contact;
        ++r.states;
    }

    // Every state, inline and without a per-axis branch: the deepest
    // penetration and the energy rise. Soundness is on_state's test
    // (plainly_sound), not repeated here.
    template <int D>
    void track_energy_and_penetration(Tracking& r, const State& s) {
        const double energy = specific_energy<D>(s, gravity_);
        if (r.states == 0) r.energy0 = energy;
        r.energy_max_rise = std::max(r.energy_max_rise, energy - r.energy0);
        r.max_penetration = std::max(r.max_penetration, walls_.penetration<D>(s.p));
    }
    // Records why a state is unsound (the first time).
    void diagnose(const State& s);
    // diagnose() unless the state is plainly sound.
    void check_sound(const State& s) {
        if (!(dim_ == 2 ? plainly_sound<2>(s) : plainly_sound<3>(s))) diagnose(s);
    }
    // Counts the contacts and keeps their events (after the first state only).
    // An impact whose ball the engine braked in the step before
    // (`before_previous` to `previous`) without a contact being counted there
    // is measured with the incoming normal speed of that arrival.
    void count_contacts(const State& previous, const State& s, ContactMask contact, bool after_first_state,
                        const State* before_previous, ContactMask previous_contact);
    // An impact over two steps (the engine stops the ball on the wall, then
    // releases it): the kept event's outgoing velocity, measured at a stop,
    // is taken from the release in the step after, if it moves away: its
    // normal component; the others stay as they were at the impact instant.
    void measure_release(const State& stopped, const State& s);
    // Keeps the apex sample refined by its neighbours' heights.
    void push_apex(Apex apex, double height_before, double height_after);
    void track_apex(Tracking& r, const State& previous, const State& s) const {
        const double height = s.p[vertical_];
        if (!r.apex_open || height > r.apex.height) {
            r.apex = Apex{s.t, height};
            r.apex_before = r.states > 0 && r.apex_open ? previous.p[vertical_] : std::nan("");
            r.apex_after = std::nan("");
            r.apex_open = true;
        } else if (std::isnan(r.apex_after)) {
            r.apex_after = height;
        }
    }
    void track_rest(Tracking& r, const State& s) const {
        const bool resting = s.p[vertical_] - floor_ <= rest_height_ && std::abs(s.v[vertical_]) <= rest_speed_;
        if (!resting) r.rest_since.reset();
        else if (!r.rest_since) r.rest_since = s.t;
    }

    StateSink* sink_;
    int dim_;
    int vertical_;
    Vec3 low_limit_, high_limit_;  // centre positions beyond which the ball has left the room (unused axes: infinite)
    WallLimits walls_;
    Tracking tracking_;
    std::int64_t contacts_ = 0, floor_contacts_ = 0, apex_count_ = 0;
    std::vector<Apex> apexes_;
    std::vector<ContactEvent> contact_events_;
    // contact_events_ measured at a stop in the last step: their index, wall
    // plane, velocities at the impact and the axes of the walls touched with them.
    struct StoppedImpact {
        std::size_t event;
        double wall;
        Vec3 incoming, outgoing;
        unsigned normal_axes;
    };
    std::vector<StoppedImpact> stopped_impacts_;
    Vec3 gravity_;
    State last_;  // the last state recorded
    std::string failure_;
    // Vertical rest: from Tracking::rest_since on, the ball stayed within rest_height_
    // of the floor with vertical speed below rest_speed_ (see summary.cpp).
    static constexpr int kRestSteps = 10;
    double floor_, rest_height_, rest_speed_, dt_;
    // A normal speed away from a wall of at most one step of gravity: a ball
    // the engine stopped on it (count_contacts, measure_release).
    double stopped_speed_;
    std::optional<double> filled_from_;
    std::int64_t fill_period_ = 0, fill_steps_ = 0;
    // What on_resolved_events measured, applied by finish().
    struct Resolved {
        std::int64_t contacts = 0, floor_contacts = 0, apex_count = 0;
        std::vector<ContactEvent> contact_events;
        std::vector<Apex> apexes;
        std::optional<double> rest_time;
        bool contacts_unbounded = false;
    };
    std::optional<Resolved> resolved_;
    // Not yet recorded, in order; the states contiguous for the sink's write_block.
    std::array<State, kBlock> pending_states_;
    std::array<ContactMask, kBlock> pending_contacts_;
    std::size_t pending_size_ = 0;
};

// Runs `sim` on `s` with its stream recorded (and passed on to `sink` when
// given): every metric of the run, with the simulator's own status, settings
// and timing. A simulator that gives up itself wins over the recorder's
// verdict on its states.
SimulatorSummary record_run(const Simulator& sim, const Scenario& s, StateSink* sink = nullptr);

}  // namespace bouncecheck
