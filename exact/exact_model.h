// The continuous-time solution of the document's damping law: the ground truth
// every error figure is measured against.
//
// The law. A ball (centre p, radius r) moves in the box [0, size_i] on each used
// axis under constant gravity g. Between contacts p follows the exact parabola
// p0 + v0 t + g t^2 / 2. A contact happens when the ball touches a wall
// (p_i = r or p_i = size_i - r) while moving into it; then the normal velocity
// component is multiplied by -alpha and every other component by beta.
//
// Choices where the law leaves room (all bounded by round-off or by the stated
// thresholds):
// - Corners/edges: walls reached at the same instant (contact times equal to a
//   relative 1e-11) are applied one after another in axis order, lower wall
//   before upper, each scaling the velocity left by the previous one; all of them
//   apply, even if beta = 0 stopped the motion towards a later one. The final
//   velocity does not depend on the order (the scalings commute); only the
//   v_before/v_after of the individual WallContact entries do.
// - Zeno with gravity perpendicular to the wall (the only nonzero gravity
//   component is along its normal and presses into it), 0 < alpha < 1,
//   0 <= beta <= 1: once the closed-form tangential travel of the infinite tail
//   stays inside the room, the tail is summed exactly (state_at evaluates any
//   hop of it in O(1)); the ball then rests on the wall with tangential velocity
//   0 if beta < 1 (infinitely many contacts scale it by beta) or unchanged if
//   beta = 1, and that axis is locked. Until the tail fits, bounces are resolved
//   one by one. The summed tail's hops are still listed in contacts() and
//   apexes(), from their closed forms, while a hop's height is at least 1e-6
//   of the room (so its absolute coordinates resolve it to 1e-11) and at most
//   kMaxListedTailHops of them;
//   the rest of the infinite sequence is summed_tail_contacts() = -1.
// - Zeno with a tangential gravity component (or a tail that never fits),
//   0 < alpha < 1: bounces are resolved one by one until the remaining
//   accumulation time R = (2u/|g_n|) / (1 - alpha) is below 1e-12 s; then the
//   axis is locked on the wall (normal velocity 0) and, if beta < 1, the other
//   velocity components are set to 0, the limit of the infinitely many
//   remaining contacts. R bounds the tail in a corner too (the other walls'
//   contacts only scale the normal speed down). Doing that R early misplaces
//   the ball by at most the hop height g_n R^2 / 8 plus |v| R, and offsets a
//   later tangential velocity by at most |g| R: all below 1e-11 in SI units
//   for |v|, |g| < 10. The solve keeps coordinates relative to the nearer
//   wall, so hops keep shrinking down to R < 1e-12 s even in a corner (no
//   round-off floor). The other axes keep moving under their gravity; a
//   locked axis stays locked (gravity is constant).
// - alpha = 0: the first impact on a wall that gravity presses into stops and
//   locks that axis. A ball at rest on such a wall from the start is locked too.
// - alpha = 1: no Zeno on a single wall (its own contacts keep the normal
//   speed); hops shrink only through beta at the other walls' contacts, so
//   they accumulate in an edge or corner that gravity presses the ball into,
//   every pressed wall at once. The contact sequence there is not periodic
//   (tests/data/exact_corner: mostly alternating, a double contact every
//   ~30, the shape of the orbit wandering), so there is no self-similar
//   closed form; bounces are resolved one by one until every pressed axis
//   has a time scale sqrt(2 E_i) / |g_i| < 1e-12 s, where E_i = v_i^2 / 2 +
//   |g_i| d_i and d_i is the distance from its pressed wall, and every
//   gravity-free axis a speed below |g| 1e-12 s (beta < 1 scales it at each
//   contact). Then those walls are locked together and, if beta < 1, every
//   velocity set to 0. E_i never grows (alpha = 1 keeps it, beta lowers it),
//   so after the lock the true ball stays within E_i / |g_i| < |g_i| 1e-24
//   of each locked wall and below sqrt(2 E_i) < |g_i| 1e-12 on its axis,
//   forever; a gravity-free axis travels at most 2 T |v_j| / (1 - beta) more
//   (T the largest time scale: no flight in the corner lasts longer than
//   2 T). The lock instant is where the accumulation is reached to within the
//   remaining hops, which no bound covers: measured against a 100-digit
//   solution, 6e-11 to 7e-8 s early or late, within how far a 1e-17 m change
//   of a wall moves the accumulation itself. A subset of two or more pressed
//   walls is locked the same way while every other pressed axis is far from
//   its wall (time scale 1e-3 s or more): the ball then slides along the edge
//   under that axis's gravity. One pressed wall alone is never locked while
//   another pressed axis moves: its micro-hops would keep scaling that axis's
//   velocity by beta at every contact, which holds the ball against the wall
//   (the law's limit is a sticking wall).
// - alpha = 1, a corner that stops shrinking: when each contact comes at the
//   other axis's turning point it loses no energy, and beta = 0 makes that
//   cycle attract (after a contact the other axis starts from rest, so it
//   turns exactly at the next one; the ratio of the two axes' time scales
//   then maps r -> sqrt((2 - r) / r), whose fixed point r = 1 is neutral).
//   The scale then decays by ~0.1% per 20,000 contacts, with no accumulation
//   in reach. A corner within 1e-15 x the room size of every pressed wall
//   that has not halved its time scale in 10,000 contacts is locked as it
//   is, with the same energy bound (tests/data/exact_corner/monte-carlo-6573:
//   2.5e-18 m, 6e-9 m/s). A larger such cycle is resolved contact by contact
//   and ends at the event cap: 5 of 100,000 Monte-Carlo scenarios, all
//   alpha = 1, beta = 0. event_cap_hit() and stalled_corner() say so; with a
//   start of ~1e-12 m/s into an elastic wall with gravity along it (the
//   sticking wall) and a run with more real contacts than the cap, they are
//   what exact gives up on.
//
// Time range: contacts(), apexes() and rest_time() describe [0, duration].
// state_at() is solved up to horizon() = duration + 2 dt, so the document
// clock's last sample (which can overshoot duration by up to dt) is exact too.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/document_clock.h"
#include "simulators/state.h"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

namespace bouncecheck {


class ExactModel {
public:
    // Bounds the memory of pathological scenarios (alpha very close to 1 with a
    // tangential gravity component): ~190 bytes per event.
    static constexpr std::int64_t kDefaultMaxEvents = 1'000'000;

    // Solves the whole run [0, horizon()] at construction. The scenario is
    // expected to be valid (see scenarios/loader.h); the start position is
    // clamped into the room.
    explicit ExactModel(const Scenario& s, std::int64_t max_events = kDefaultMaxEvents);

    // Exact state at t, O(log segments) (a Cursor walks a stream's times in
    // O(1)). At a contact instant it returns the
    // velocity after the contact. The position is always inside [r, size - r].
    State state_at(double t) const;

    // Every contact in [0, duration] in time order; a corner gives one per
    // wall, with the same t. The summed Zeno tail's contacts are listed from
    // their closed forms (see listed_tail_contacts()) down to hops whose
    // remaining accumulation time is 1e-12 s, as a resolved Zeno lists its
    // own; the infinitely many after those are summed_tail_contacts().
    const std::vector<WallContact>& contacts() const { return contacts_; }
    // The apex (Apex, simulators/state.h: the centre's vertical coordinate, not
    // the height above the floor) of every flight in [0, duration]: the
    // turning point of the vertical coordinate, a top (or a bottom if gravity
    // points up). Includes the initial one if the ball starts rising or
    // vertically at rest in flight, and the listed hops of a summed Zeno tail
    // on the floor (or ceiling): see listed_tail_apexes().
    const std::vector<Apex>& apexes() const { return apexes_; }
    // The part of contacts() and of apexes() that the summed Zeno tail lists
    // (empty if none). Hop k = 0, 1, ... of the tail (the one after the bounce
    // that starts it, at t0 with normal speed u) starts at
    // t0 + flight0 (1 - alpha^k) / (1 - alpha), flight0 = 2 u / g; contact
    // k = 1, 2, ... ends hop k - 1 with normal speed u alpha^(k-1) in and
    // u alpha^k out, tangential velocity v0 beta^(k-1) in and v0 beta^k out;
    // hop k's apex is at its middle, u alpha^k / g later, u^2 alpha^2k / (2 g)
    // from the wall. Times and velocities are the ones state_at gives at the
    // hop boundaries (the same alpha^k, the same hop starts).
    std::span<const WallContact> listed_tail_contacts() const {
        return std::span(contacts_).subspan(tail_contacts_.first, tail_contacts_.count);
    }
    std::span<const Apex> listed_tail_apexes() const {
        return std::span(apexes_).subspan(tail_apexes_.first, tail_apexes_.count);
    }
    // At most this many hops of a summed tail are listed (memory: ~100 bytes
    // a hop); only alpha above ~0.993 reaches it.
    static constexpr std::int64_t kMaxListedTailHops = 4096;
    // When the vertical axis came to rest on its floor (Zeno accumulation time,
    // threshold lock or alpha = 0 impact), if within duration.
    std::optional<double> rest_time() const { return rest_time_; }
    // -1: an infinite tail of contacts was summed in closed form (at most one per
    // run: it leaves no gravity on free axes); its first hops are listed in
    // contacts(), the rest are uncounted. 0: none was.
    std::int64_t summed_tail_contacts() const { return tail_ ? -1 : 0; }
    // True if the run stopped at max_events contact instants before the horizon;
    // the solution after the last segment start is then unreliable.
    bool event_cap_hit() const { return event_cap_hit_; }
    // With the event cap hit in an alpha = 1 corner whose contacts had locked
    // into a cycle that stopped shrinking: the cycle's time scale (s).
    std::optional<double> stalled_corner() const;
    double horizon() const { return horizon_; }

    // Calls sink(const State&) at the document clock's times (t_0 = 0,
    // t_{n+1} = t_n + dt while |t_n| < |duration|): document_step_count + 1
    // rows. A cursor makes the whole sequence O(rows + segments).
    template <class Sink>
    void sample_document_clock(Sink&& sink) const {
        Cursor at(*this);
        for (DocumentClock clock(dt_, duration_);; clock.advance()) {
            sink(at.state(clock.t()));
            if (!clock.running()) break;
        }
    }

    // Whether the state is the same at t and at every later time.
    bool still_after(double t) const {
        return t >= segments_.back().t0 && still_from(segments_.size() - 1, t);
    }

    // As sample_document_clock, but stops after the first sample from which
    // the state stays the same to the end of the run (the ball at rest, not
    // moving along the wall either): returns the clock at that sample, so
    // the caller can hand the rest over (PeriodicTail); nothing if it sampled
    // to the end.
    template <class Sink>
    std::optional<DocumentClock> sample_document_clock_until_still(Sink&& sink) const {
        Cursor at(*this);
        for (DocumentClock clock(dt_, duration_);; clock.advance()) {
            const double t = clock.t();
            sink(at.state(t));
            if (!clock.running()) return std::nullopt;
            if (at.segment() + 1 == segments_.size() && still_from(at.segment(), t)) return clock;
        }
    }

private:
    // The hop of the summed Zeno tail (ZenoTail) that a time falls in, with
    // what evaluating it needs: a cursor keeps the last one, so a stream's
    // samples within one hop cost no pow or log.
    struct TailHop {
        double k = -1;  // hop index; -1: none yet
        double start = 0, next_start = 0;  // tau at which hop k and hop k + 1 start
        double alpha_k = 0, beta_k = 0;
        double flight = 0;                 // hop k's flight time
        double full_hops_travel_time = 0;  // sum_{i<k} flight0 (alpha beta)^i
    };

public:
    // The solution at a stream's sample times, which do not decrease: O(1)
    // amortized per sample where state_at searches (it walks the segments
    // forward and keeps the Zeno tail's current hop). The same states as
    // state_at, bit for bit; a time before the last one is searched for.
    class Cursor {
    public:
        explicit Cursor(const ExactModel& model) : model_(&model) {}
        State state(double t) {
            const std::vector<Segment>& segments = model_->segments_;
            if (!(t >= segments[segment_].t0) && (segment_ > 0 || t != t)) {
                segment_ = model_->segment_of(t);  // earlier than the last time, or NaN
            } else {
                while (segment_ + 1 < segments.size() && segments[segment_ + 1].t0 <= t) ++segment_;
            }
            return model_->evaluate(segment_, t, hop_);
        }
        // state(t).p at each state's time, bit for bit: a stretch of times
        // inside one free-flight segment in one loop, positions only.
        void positions(std::span<const State> at, Vec3* out);
        std::size_t segment() const { return segment_; }

    private:
        const ExactModel* model_;
        std::size_t segment_ = 0;
        TailHop hop_;
    };

private:
    // Uniform motion law from t0 until the next segment: the parabola with
    // acceleration `accel`, which is gravity on free axes and 0 on locked ones
    // (their velocity is 0 too), unless zeno_tail says it is the summed tail.
    struct Segment {
        double t0;
        Vec3 p0, v0, accel;
        unsigned locked;  // bit i: axis i rests on a wall
        bool zeno_tail;
    };
    // The infinite hop sequence after a bounce on `axis` with gravity purely
    // along its normal. Hop k starts at flight0 (1 - alpha^k) / (1 - alpha) with
    // normal speed u alpha^k and tangential velocity v0 beta^k.
    struct ZenoTail {
        double t0;
        Vec3 p0, v0;  // just after the bounce that starts the tail
        int axis, side;
        double u, g, flight0, length;
        Vec3 rest_p, rest_v;  // at t0 + length
    };
    // The evolving state of the solve. Each coordinate is kept as a distance
    // from the nearer wall, not as an absolute coordinate: hops of a ball
    // Zeno-bouncing in a corner then keep full relative precision instead of
    // being quantized to ulp(size), which round-off would keep alive forever.
    struct Motion {
        double t;
        double offset[3];  // distance of the centre from its anchor wall, in [0, span / 2]
        int anchor[3];     // -1 lower wall, +1 upper wall
        Vec3 v, accel;
        unsigned locked;
    };

    void solve(const Scenario& s, std::int64_t max_events);
    void push_segment(const Motion& m, bool zeno_tail = false);
    void record_apex(const Motion& m, double t_end);
    void apply_contacts(Motion& m, const bool (&hit)[3][2]);
    void settle_pressed_walls(Motion& m, const bool (&hit)[3][2]);
    bool sum_tail(Motion& m, int axis, int side);
    void list_tail_hops();
    void lock_corner(Motion& m);
    void lock_axis(Motion& m, int axis, int side, bool zero_other_velocities);
    void lock_resting_axes(Motion& m);
    double wall(int axis, int side) const { return side < 0 ? lo_[axis] : hi_[axis]; }
    double distance_to_wall(const Motion& m, int axis, int side) const;
    void place(Motion& m, int axis, int anchor, double offset) const;
    void move(Motion& m, int axis, double delta) const;
    Vec3 position(const Motion& m) const;
    // The segment that holds t: the last to start by t (0 before the first).
    std::size_t segment_of(double t) const;
    State evaluate(std::size_t segment, double t, TailHop& hop) const;
    // evaluate's position on a segment that is not the Zeno tail.
    Vec3 flight_position(const Segment& s, double t) const;
    // Whether evaluate(segment, t') gives the same position and velocity for
    // every t' >= t.
    bool still_from(std::size_t segment, double t) const;
    State tail_state(double t, TailHop& hop) const;
    TailHop tail_hop(double tau, double alpha_k_estimate) const;
    void clamp_into_room(Vec3& p) const;

    int dim_;
    double alpha_, beta_;
    double dt_, duration_;
    double end_;      // |duration|
    double horizon_;  // end_ + 2 |dt|
    double lo_[3], hi_[3], size_[3];  // centre range per axis, room size

    std::vector<Segment> segments_;
    std::vector<WallContact> contacts_;
    std::vector<Apex> apexes_;
    std::optional<ZenoTail> tail_;
    // Where the summed tail's listed contacts and apexes are in contacts_ and apexes_.
    struct Listed {
        std::size_t first = 0, count = 0;
    } tail_contacts_, tail_apexes_;
    std::optional<double> rest_time_;
    bool event_cap_hit_ = false;
    // lock_corner's watch on an alpha = 1 corner that may have stopped
    // shrinking: its time scale when last halved, and contacts since.
    struct StallWatch {
        double scale = std::numeric_limits<double>::infinity();
        std::int64_t contacts = 0;
        int axes = 0;  // pressed axes when last watched
    } stall_;
};

}  // namespace bouncecheck
