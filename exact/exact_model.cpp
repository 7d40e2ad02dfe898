#include "exact/exact_model.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace bouncecheck {
namespace {

constexpr double kNever = std::numeric_limits<double>::infinity();

// Walls whose contact times agree to this relative tolerance are reached at
// the same instant (corner/edge): designed-equal times differ by a few ulps.
constexpr double kSimultaneous = 1e-11;

// Zeno lock threshold for tails that cannot be summed in closed form (see the
// header): the remaining accumulation time on one wall (alpha < 1), or the
// time scale sqrt(2 E_i) / |g_i| of every pressed axis in a corner (alpha = 1).
constexpr double kLockTime = 1e-12;
// alpha = 1 corners (lock_corner): a pressed axis with a time scale above
// kFarTime is not part of an accumulation whose axes are below kLockTime;
// a corner within kStallHeight x the room size of every pressed wall that
// has not halved its scale in kStallEvents contacts has stopped shrinking.
constexpr double kFarTime = 1e-3;
constexpr double kStallHeight = 1e-15;
constexpr std::int64_t kStallEvents = 10'000;

// Typical runs have tens to hundreds of contacts: one allocation per vector.
constexpr std::size_t kInitialCapacity = 256;

// Time until the centre, at distance d >= 0 from a wall and approaching it at
// speed u (negative: receding) with acceleration a towards it, reaches the wall
// moving in; kNever if it never does. Roots of d - u t - a t^2 / 2 = 0 in the
// cancellation-free forms q / a and c / q, q = -(b + sign(b) sqrt(disc)) / 2.
double time_to_wall(double d, double u, double a) {
    if (d <= 0) {
        // Touching: a contact now if moving in. Receding (just bounced), the
        // return is the factored root -2u/a, so the bounce is never re-detected.
        if (u > 0) return 0;
        if (u < 0 && a > 0) return -2 * u / a;
        return kNever;
    }
    if (u >= 0) {
        // The smaller positive root c / q. With a < 0 the wall may be out of
        // reach (disc < 0) or only grazed at zero normal speed (disc = 0).
        const double disc = u * u + 2 * a * d;
        if (!(disc > 0)) return kNever;
        return 2 * d / (u + std::sqrt(disc));
    }
    // Receding: only an acceleration towards the wall brings it back (root q / a).
    if (!(a > 0)) return kNever;
    return (std::sqrt(u * u + 2 * a * d) - u) / a;
}

Vec3 position_after(const Vec3& p, const Vec3& v, const Vec3& a, double tau) {
    return p + tau * v + (0.5 * tau * tau) * a;
}

bool is_locked(unsigned locked, int axis) { return (locked >> axis) & 1u; }

}  // namespace

ExactModel::ExactModel(const Scenario& s, std::int64_t max_events)
    : dim_(s.dim),
      alpha_(s.alpha),
      beta_(s.beta),
      dt_(s.dt),
      duration_(s.duration),
      end_(std::abs(s.duration)),
      horizon_(std::abs(s.duration) + 2 * std::abs(s.dt)) {
    for (int i = 0; i < 3; ++i) {
        lo_[i] = s.radius;
        hi_[i] = s.room[i] - s.radius;
        size_[i] = s.room[i];
    }
    segments_.reserve(kInitialCapacity);
    contacts_.reserve(kInitialCapacity);
    apexes_.reserve(kInitialCapacity);
    solve(s, max_events);
}

// Event-driven: from each segment start, the earliest wall reached moving in
// ends the segment; contacts are applied there and a new segment starts.
void ExactModel::solve(const Scenario& s, std::int64_t max_events) {
    Motion m{0.0, {0, 0, 0}, {-1, -1, -1}, Vec3::Zero(), Vec3::Zero(), 0u};
    for (int i = 0; i < dim_; ++i) {
        const double p = std::clamp(s.position[i], lo_[i], hi_[i]);
        // Measured from the nearer wall, so a start on a wall is exactly on it.
        if (p - lo_[i] <= hi_[i] - p)
            place(m, i, -1, p - lo_[i]);
        else
            place(m, i, +1, hi_[i] - p);
        m.v[i] = s.velocity[i];
        m.accel[i] = s.gravity[i];
    }
    lock_resting_axes(m);

    for (std::int64_t events = 0;; ++events) {
        push_segment(m);

        double tau[3][2];  // per axis: time to the lower, upper wall
        double first = kNever;
        for (int i = 0; i < dim_; ++i) {
            if (is_locked(m.locked, i)) {
                tau[i][0] = tau[i][1] = kNever;
                continue;
            }
            tau[i][0] = time_to_wall(distance_to_wall(m, i, -1), -m.v[i], -m.accel[i]);
            tau[i][1] = time_to_wall(distance_to_wall(m, i, +1), m.v[i], m.accel[i]);
            first = std::min({first, tau[i][0], tau[i][1]});
        }
        record_apex(m, std::min(m.t + first, horizon_));
        if (!(m.t + first <= horizon_)) break;  // also when no wall is ever reached
        if (events == max_events) {
            event_cap_hit_ = true;
            break;
        }

        // Advance to the event. The walls reached are snapped onto their plane
        // so round-off never lets the ball drift through them.
        bool hit[3][2] = {};
        const double simultaneous = first * (1 + kSimultaneous);
        for (int i = 0; i < dim_; ++i) {
            if (is_locked(m.locked, i)) continue;
            move(m, i, first * m.v[i] + 0.5 * first * first * m.accel[i]);
            m.v[i] += first * m.accel[i];
            for (int side = 0; side < 2; ++side) {
                hit[i][side] = tau[i][side] <= simultaneous;
                if (hit[i][side]) place(m, i, 2 * side - 1, 0.0);
            }
        }
        m.t += first;
        apply_contacts(m, hit);
        settle_pressed_walls(m, hit);
        lock_resting_axes(m);
    }
}

double ExactModel::distance_to_wall(const Motion& m, int axis, int side) const {
    if (m.anchor[axis] == side) return m.offset[axis];
    return std::max(0.0, (hi_[axis] - lo_[axis]) - m.offset[axis]);
}

// Sets the coordinate `offset` from the `anchor` wall, clamped into the room
// and re-anchored to the nearer wall.
void ExactModel::place(Motion& m, int axis, int anchor, double offset) const {
    const double span = hi_[axis] - lo_[axis];
    offset = std::clamp(offset, 0.0, span);
    if (offset > 0.5 * span) {
        offset = span - offset;
        anchor = -anchor;
    }
    m.offset[axis] = offset;
    m.anchor[axis] = anchor;
}

// Moves the coordinate by `delta` along the axis.
void ExactModel::move(Motion& m, int axis, double delta) const {
    place(m, axis, m.anchor[axis], m.offset[axis] - m.anchor[axis] * delta);
}

Vec3 ExactModel::position(const Motion& m) const {
    Vec3 p = Vec3::Zero();
    for (int i = 0; i < dim_; ++i) p[i] = wall(i, m.anchor[i]) - m.anchor[i] * m.offset[i];
    return p;
}

void ExactModel::push_segment(const Motion& m, bool zeno_tail) {
    const Segment segment{m.t, position(m), m.v, m.accel, m.locked, zeno_tail};
    // A segment of zero length (contact at its start) is superseded by the
    // state after the contact, so segment start times strictly increase.
    if (!segments_.empty() && segments_.back().t0 == m.t)
        segments_.back() = segment;
    else
        segments_.push_back(segment);
}

// The vertical turning point of the segment [m.t, t_end), if any.
void ExactModel::record_apex(const Motion& m, double t_end) {
    const int z = dim_ - 1;
    if (m.accel[z] == 0) return;  // no vertical gravity, or resting on the floor
    const double tau = -m.v[z] / m.accel[z];
    const double t = m.t + tau;
    if (!(tau >= 0 && t < t_end && t <= end_)) return;
    const double start = wall(z, m.anchor[z]) - m.anchor[z] * m.offset[z];
    const double height = start + tau * m.v[z] + 0.5 * tau * tau * m.accel[z];
    apexes_.push_back({t, std::clamp(height, lo_[z], hi_[z])});
}

// Walls in axis order, lower before upper; each scales the velocity the
// previous one left (the scalings commute, so only the log depends on order).
void ExactModel::apply_contacts(Motion& m, const bool (&hit)[3][2]) {
    const Vec3 p = position(m);
    for (int i = 0; i < dim_; ++i) {
        for (int side = 0; side < 2; ++side) {
            if (!hit[i][side]) continue;
            WallContact contact{m.t, i, 2 * side - 1, p, m.v, Vec3::Zero()};
            for (int j = 0; j < dim_; ++j) m.v[j] *= j == i ? -alpha_ : beta_;
            contact.v_after = m.v;
            if (m.t <= end_) contacts_.push_back(contact);
        }
    }
}

// Zeno: after a bounce on a wall that gravity presses into, either sum the
// infinite tail in closed form or, once the remaining hops are negligible,
// lock the axis (choices and error bound in the header). alpha = 0 needs
// neither: the normal velocity is already 0 and lock_resting_axes locks it.
// With alpha = 1 a wall's hops shrink only through beta at the other walls'
// contacts, so they can only accumulate together, in a corner: lock_corner.
void ExactModel::settle_pressed_walls(Motion& m, const bool (&hit)[3][2]) {
    if (alpha_ == 1) {
        lock_corner(m);
        return;
    }
    if (!(alpha_ > 0 && alpha_ < 1)) return;
    for (int i = 0; i < dim_; ++i) {
        for (int side = 0; side < 2; ++side) {
            const int sign = 2 * side - 1;
            if (!hit[i][side] || !(m.accel[i] * sign > 0)) continue;
            if (sum_tail(m, i, sign)) return;  // the only pressed wall: gravity is along its normal
            const double u = std::abs(m.v[i]), g = std::abs(m.accel[i]);
            if (2 * u / g / (1 - alpha_) < kLockTime) lock_axis(m, i, sign, true);
        }
    }
}

// alpha = 1 in an edge or corner: the walls that gravity presses the ball
// into (the pressed axes) are locked together once each pressed axis's energy
// E_i = v_i^2 / 2 + |g_i| d_i (d_i: distance from its pressed wall) gives a
// time scale T_i = sqrt(2 E_i) / |g_i| below kLockTime. E_i never grows (its
// own wall keeps |v_i|, the others scale v_i by beta), so the ball stays
// within E_i / |g_i| of those walls and below sqrt(2 E_i) on their axes
// forever: that bounds the lock's error (header). Every gravity-free axis must
// have slowed below |g| kLockTime too, as beta < 1 does at each contact;
// beta = 1 keeps its velocity, which contacts never change then.
// - Two or more tiny pressed axes are locked while another pressed axis is
//   still far (T_f >= kFarTime): the ball then slides along the edge. One
//   nearer than that keeps being damped by the edge's contacts, so the solve
//   goes on until it is tiny too; a lone tiny wall is never locked while
//   another pressed axis moves (the law makes that wall hold the ball).
// - A corner whose scale stops shrinking (no halving of the largest T_i in
//   kStallEvents contacts) has locked its contacts into a cycle that loses
//   almost no energy, each at the other wall's turning point (beta = 0 makes
//   that cycle attract). Within kStallHeight x the room size of every pressed
//   wall it is locked as it is; a larger one is resolved on and, if it ends
//   at the event cap, stalled_corner() names it.
void ExactModel::lock_corner(Motion& m) {
    unsigned tiny = 0, pressed = 0, far = 0;
    bool micro = true;
    double g_norm = 0, scale = 0;
    for (int i = 0; i < dim_; ++i) {
        if (is_locked(m.locked, i) || m.accel[i] == 0) continue;
        pressed |= 1u << i;
        const double g = std::abs(m.accel[i]);
        g_norm = std::hypot(g_norm, g);
        const double energy = 0.5 * m.v[i] * m.v[i] + g * distance_to_wall(m, i, m.accel[i] < 0 ? -1 : +1);
        const double time_scale = std::sqrt(2 * energy) / g;
        if (time_scale < kLockTime) tiny |= 1u << i;
        if (time_scale >= kFarTime)
            far |= 1u << i;
        else
            scale = std::max(scale, time_scale);  // the corner's own axes
        micro = micro && energy / g < kStallHeight * size_[i];
    }
    if (pressed == 0) return;
    bool lock = tiny == pressed || (std::popcount(tiny) >= 2 && (tiny | far) == pressed);
    const int corner_axes = std::popcount(pressed & ~far);
    if (!lock && corner_axes < 2) {
        stall_ = {};  // no corner to watch
    } else if (!lock) {
        // Restart the watch whenever the corner has shrunk to half its scale.
        if (!(scale >= 0.5 * stall_.scale)) stall_ = {scale, 0, corner_axes};
        ++stall_.contacts;
        if (micro && stall_.contacts >= kStallEvents) {
            lock = true;
            tiny = pressed;
        }
    }
    if (!lock) return;
    if (beta_ < 1)
        for (int j = 0; j < dim_; ++j)
            if (!is_locked(m.locked, j) && m.accel[j] == 0 && !(std::abs(m.v[j]) < g_norm * kLockTime)) return;
    for (int i = 0; i < dim_; ++i)
        if ((tiny >> i) & 1u) lock_axis(m, i, m.accel[i] < 0 ? -1 : +1, true);
}

std::optional<double> ExactModel::stalled_corner() const {
    if (!event_cap_hit_ || stall_.axes < 2 || stall_.contacts < kStallEvents) return std::nullopt;
    return stall_.scale;
}

// After a bounce on `axis` with gravity purely along its normal, the hops form
// a geometric series: hop k lasts flight0 alpha^k with tangential velocity
// v beta^k, so the tail lasts flight0 / (1 - alpha) and travels
// v flight0 / (1 - alpha beta). Summed only if the hops stay clear of every
// other wall; otherwise the caller resolves the next bounce and retries.
bool ExactModel::sum_tail(Motion& m, int axis, int side) {
    if (tail_ || !(beta_ >= 0 && beta_ <= 1)) return false;
    for (int j = 0; j < dim_; ++j)
        if (j != axis && m.accel[j] != 0) return false;  // tangential gravity: no geometric series
    const double u = std::abs(m.v[axis]), g = std::abs(m.accel[axis]);
    if (!(u > 0) || !(u * u / (2 * g) < hi_[axis] - lo_[axis])) return false;  // hop reaches the opposite wall
    const double flight0 = 2 * u / g;
    const double travel_time = flight0 / (1 - alpha_ * beta_);  // sum of hop_k beta^k
    Motion rest = m;
    rest.t = m.t + flight0 / (1 - alpha_);
    rest.v.setZero();  // beta < 1: infinitely many contacts stop the sliding
    for (int j = 0; j < dim_; ++j) {
        if (j == axis || m.v[j] == 0) continue;
        const double travel = m.v[j] * travel_time;
        // Travel is monotone, so its end decides; it must not reach the wall.
        if (!(std::abs(travel) < distance_to_wall(m, j, travel > 0 ? +1 : -1))) return false;
        move(rest, j, travel);
        if (beta_ == 1) rest.v[j] = m.v[j];
    }
    lock_axis(rest, axis, side, false);
    tail_ = ZenoTail{m.t, position(m), m.v, axis, side, u, g, flight0, rest.t - m.t, position(rest), rest.v};
    push_segment(m, true);
    list_tail_hops();
    m = rest;
    return true;
}

// The summed tail's hops in contacts_ and apexes_, from their closed forms
// (header: listed_tail_contacts): hop k while the accumulation time it leaves,
// flight0 alpha^k / (1 - alpha), is at least kLockTime (where a resolved Zeno
// locks), within [0, duration], at most kMaxListedTailHops. alpha^k, the hop
// starts and the tangential travel are tail_hop's expressions, so a listed
// contact has the velocity and position that tail_state gives at its hop's
// start. Nothing here feeds the segments: the states do not change.
void ExactModel::list_tail_hops() {
    const ZenoTail& z = *tail_;
    const auto hop_start = [&](double k) { return z.flight0 * (1 - std::pow(alpha_, k)) / (1 - alpha_); };
    // Apexes are turning points of the vertical coordinate: with gravity only
    // along the tail's axis, the tail has some only if that axis is vertical.
    const bool vertical = z.axis == dim_ - 1;
    const double wall_at = wall(z.axis, z.side);
    tail_contacts_ = {contacts_.size(), 0};
    tail_apexes_ = {apexes_.size(), 0};
    double last_t = z.t0;
    for (double k = 0; k < static_cast<double>(kMaxListedTailHops); k += 1) {
        const double alpha_k = std::pow(alpha_, k);
        if (!(z.flight0 * alpha_k / (1 - alpha_) >= kLockTime)) break;
        const double u_k = z.u * alpha_k;  // hop k's normal speed, leaving the wall
        // A hop is listed while its height is resolved in the wall's
        // coordinate to 1e-11 of itself (apexes and contacts are absolute
        // coordinates): down to 1e-6 of the room, hops far shorter than any dt.
        if (!(u_k * u_k / (2 * z.g) >= 1e-6 * size_[z.axis])) break;
        const double start = z.t0 + hop_start(k);
        if (vertical) {
            const double t = start + u_k / z.g;
            if (!(t <= end_)) break;
            const double height = wall_at - z.side * (u_k * u_k / (2 * z.g));
            apexes_.push_back({t, std::clamp(height, lo_[z.axis], hi_[z.axis])});
            ++tail_apexes_.count;
        }
        // The contact that ends hop k and starts hop k + 1. Past the double
        // resolution of the clock (a long run's late tail) times stop growing.
        const double t = z.t0 + hop_start(k + 1);
        if (!(t <= end_ && t > last_t)) break;
        last_t = t;
        WallContact c{t, z.axis, z.side, Vec3::Zero(), std::pow(beta_, k) * z.v0, std::pow(beta_, k + 1) * z.v0};
        c.v_before[z.axis] = z.side * u_k;
        // The contact as state_at gives it, which at a contact instant is
        // the state after it: the closed-form instant, moved up by an ulp
        // or two where round-off leaves it at the end of the hop before.
        State at = state_at(c.t);
        for (int ulps = 0; ulps < 8 && z.side * at.v[z.axis] > 0; ++ulps) at = state_at(c.t = std::nextafter(c.t, end_));
        c.p = at.p;
        c.v_after = at.v;
        contacts_.push_back(c);
        ++tail_contacts_.count;
    }
}

void ExactModel::lock_axis(Motion& m, int axis, int side, bool zero_other_velocities) {
    place(m, axis, side, 0.0);
    m.v[axis] = 0;
    m.accel[axis] = 0;
    m.locked |= 1u << axis;
    if (zero_other_velocities && beta_ < 1) m.v.setZero();
    if (axis == dim_ - 1 && !rest_time_ && m.t <= end_) rest_time_ = m.t;
}

// A ball on a wall with no normal velocity and gravity pressing into it stays:
// at the start, or after an alpha = 0 impact.
void ExactModel::lock_resting_axes(Motion& m) {
    for (int i = 0; i < dim_; ++i) {
        if (is_locked(m.locked, i) || m.v[i] != 0) continue;
        if (m.accel[i] < 0 && distance_to_wall(m, i, -1) == 0)
            lock_axis(m, i, -1, false);
        else if (m.accel[i] > 0 && distance_to_wall(m, i, +1) == 0)
            lock_axis(m, i, +1, false);
    }
}

std::size_t ExactModel::segment_of(double t) const {
    // Every sample after the last event (the ball at rest, typically) is in
    // the last segment: no search.
    if (t >= segments_.back().t0) return segments_.size() - 1;
    const auto after = std::upper_bound(segments_.begin(), segments_.end(), t,
                                        [](double time, const Segment& s) { return time < s.t0; });
    return after == segments_.begin() ? 0 : static_cast<std::size_t>(after - segments_.begin()) - 1;
}

State ExactModel::state_at(double t) const {
    TailHop hop;
    return evaluate(segment_of(t), t, hop);
}

State ExactModel::evaluate(std::size_t segment, double t, TailHop& hop) const {
    const Segment& s = segments_[segment];
    if (s.zeno_tail) return tail_state(t, hop);
    return State{t, flight_position(s, t), s.v0 + (t - s.t0) * s.accel};
}

Vec3 ExactModel::flight_position(const Segment& s, double t) const {
    Vec3 p = position_after(s.p0, s.v0, s.accel, t - s.t0);
    clamp_into_room(p);
    return p;
}

void ExactModel::Cursor::positions(std::span<const State> at, Vec3* out) {
    const std::vector<Segment>& segments = model_->segments_;
    for (std::size_t i = 0; i < at.size();) {
        out[i] = state(at[i].t).p;  // moves to the segment that holds the time
        const Segment& s = segments[segment_];
        ++i;
        if (s.zeno_tail) continue;
        // The times that state() would evaluate on this segment too.
        const double next = segment_ + 1 < segments.size() ? segments[segment_ + 1].t0
                                                           : std::numeric_limits<double>::infinity();
        for (; i < at.size() && at[i].t >= at[i - 1].t && at[i].t < next; ++i)
            out[i] = model_->flight_position(s, at[i].t);
    }
}

bool ExactModel::still_from(std::size_t segment, double t) const {
    const Segment& s = segments_[segment];
    if (s.zeno_tail) {
        // tail_state's own test for the rest after the tail: once it holds at
        // t it holds at every later t (tau grows, the estimate falls).
        const ZenoTail& z = *tail_;
        const double tau = t - z.t0;
        const bool after_tail = !(tau < z.length && 1 - tau * (1 - alpha_) / z.flight0 > 0);
        return after_tail && z.rest_v == Vec3::Zero();
    }
    // A parabola with no velocity and no acceleration: p0 plus exact zeros.
    return s.v0 == Vec3::Zero() && s.accel == Vec3::Zero();
}

// Hop k of the tail starts at flight0 (1 - alpha^k) / (1 - alpha): invert that
// for k, then evaluate the hop's parabola and the tangential travel so far.
State ExactModel::tail_state(double t, TailHop& hop) const {
    const ZenoTail& z = *tail_;
    const double tau = t - z.t0;
    const double alpha_k_estimate = 1 - tau * (1 - alpha_) / z.flight0;
    if (!(tau < z.length && alpha_k_estimate > 0)) return State{t, z.rest_p, z.rest_v};
    // The hop is the last one to start by tau; hop starts grow with k, so a
    // kept hop whose span holds tau is that one.
    if (!(hop.k >= 0 && hop.start <= tau && tau < hop.next_start)) hop = tail_hop(tau, alpha_k_estimate);
    const double u = z.u * hop.alpha_k;
    const double since_bounce = std::clamp(tau - hop.start, 0.0, hop.flight);
    const double rise = std::max(0.0, since_bounce * (u - 0.5 * z.g * since_bounce));
    // Tangential: sum_{i<k} flight0 alpha^i beta^i of full hops, then this one.
    const double travel_time = hop.full_hops_travel_time + hop.beta_k * since_bounce;
    State out{t, z.p0 + travel_time * z.v0, hop.beta_k * z.v0};
    out.p[z.axis] = wall(z.axis, z.side) - z.side * rise;
    out.v[z.axis] = -z.side * (u - z.g * since_bounce);
    clamp_into_room(out.p);
    return out;
}

ExactModel::TailHop ExactModel::tail_hop(double tau, double alpha_k_estimate) const {
    const ZenoTail& z = *tail_;
    const auto hop_start = [&](double k) { return z.flight0 * (1 - std::pow(alpha_, k)) / (1 - alpha_); };
    double k = tau > 0 ? std::floor(std::log(alpha_k_estimate) / std::log(alpha_)) : 0;
    // The logarithm can land a hop off at a hop boundary. Past alpha^k = 0
    // the starts stop growing: no later hop starts by tau.
    while (k > 0 && hop_start(k) > tau) k -= 1;
    while (std::pow(alpha_, k + 1) > 0 && hop_start(k + 1) <= tau) k += 1;
    TailHop hop;
    hop.k = k;
    hop.start = hop_start(k);
    hop.next_start = hop_start(k + 1);
    hop.alpha_k = std::pow(alpha_, k);
    hop.beta_k = std::pow(beta_, k);
    hop.flight = z.flight0 * hop.alpha_k;
    const double alpha_beta = alpha_ * beta_;
    hop.full_hops_travel_time = z.flight0 * (1 - std::pow(alpha_beta, k)) / (1 - alpha_beta);
    return hop;
}

void ExactModel::clamp_into_room(Vec3& p) const {
    for (int i = 0; i < dim_; ++i) p[i] = std::clamp(p[i], lo_[i], hi_[i]);
}

}  // namespace bouncecheck
