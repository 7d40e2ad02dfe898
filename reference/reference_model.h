// `reference`: the seed document's model, reproduced bit for bit.
//
// One step is the document's EulersPosition followed by EulersVelocity, with its
// order of operations and its rounding:
//   position: p = p + v*dt; clamp below, then above (the matrix products of the
//             MATLAB code keep a component or replace it by the wall value);
//   velocity: v = v + g*dt; test contacts at the new, clamped position; if any
//             lower wall is touched multiply by the lower damping diagonal, then
//             if any upper wall is touched by the upper one. The diagonal is
//             built as `in_bounds*(alpha+beta) - alpha`, so a tangential factor
//             is (alpha+beta)-alpha, which is not always beta in doubles.
// In 2D the document keeps the lower-left corner of the drawn rectangle
// (centre - r) and tests `q > 0`, `q + 2r < size`; in 3D it keeps the centre
// and tests `p - r > 0`, `p + r < size`. Both are reproduced as written.
//
// Signed zeros: the MATLAB matrix products start their sums from +0, so a zero
// result is +0. The step does the same (`+ 0.0` where a -0 could arise).
//
// Subnormals: in the Zeno regime tangential velocities decay by beta at every
// floor contact into the subnormal range, where hardware multiplication is
// about 14x slower, and a subnormal times beta can be a fixed point (it never
// reaches zero). Once a velocity component is subnormal the step keeps the
// exact IEEE result but computes products with a subnormal operand in integer
// arithmetic (exact_product_small below), so no result bit changes and no step
// slows down; before that it is the plain hardware step.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/document_clock.h"
#include "simulators/state.h"

#include <array>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>

namespace bouncecheck {

namespace detail {

// IEEE double product x*y, correctly rounded, for |x| subnormal (or zero) and y
// finite, computed without subnormal hardware arithmetic. Falls back to the
// hardware product where the result leaves the subnormal range.
inline double exact_product_small(double x, double y) {
    const std::uint64_t xb = std::bit_cast<std::uint64_t>(x);
    const std::uint64_t yb = std::bit_cast<std::uint64_t>(y);
    const std::uint64_t sign = (xb ^ yb) & 0x8000000000000000ull;
    const std::uint64_t k = xb & 0x000FFFFFFFFFFFFFull;  // |x| = k * 2^-1074
    const int y_exp = static_cast<int>((yb >> 52) & 0x7FF);
    if (k == 0 || (yb & 0x7FFFFFFFFFFFFFFFull) == 0) return std::bit_cast<double>(sign);
    if (y_exp == 0 || y_exp == 0x7FF) return x * y;  // subnormal or non-finite y: rare
    const std::uint64_t m = (yb & 0x000FFFFFFFFFFFFFull) | 0x0010000000000000ull;
    const int shift = 1075 - y_exp;  // |y| = m * 2^(y_exp - 1075)
    if (shift <= 0) return x * y;    // |y| >= 2^52: result may be normal
    // |x*y| = k*m * 2^-shift * 2^-1074: round k*m / 2^shift to an integer,
    // ties to even; that integer's bits are the result (also at 2^52 = DBL_MIN).
    if (k < (1ull << 11) && shift < 64) {
        // The common case deep in the Zeno regime (k a few units, y = beta or
        // alpha): the product fits 64 bits.
        const std::uint64_t p = k * m;
        const std::uint64_t q = p >> shift;
        const std::uint64_t rem = p - (q << shift);
        const std::uint64_t half = 1ull << (shift - 1);
        const std::uint64_t rounded = q + ((rem > half || (rem == half && (q & 1))) ? 1 : 0);
        if (rounded >= (1ull << 53)) return x * y;  // normal beyond 2*DBL_MIN (|y| > 1)
        return std::bit_cast<double>(sign | rounded);
    }
    const unsigned __int128 product = static_cast<unsigned __int128>(k) * m;
    if (shift >= 110) return std::bit_cast<double>(sign);  // product < 2^105: below half of 2^-1074
    const unsigned __int128 quotient = product >> shift;
    const unsigned __int128 remainder = product - (quotient << shift);
    const unsigned __int128 half = static_cast<unsigned __int128>(1) << (shift - 1);
    unsigned __int128 rounded = quotient;
    if (remainder > half || (remainder == half && (quotient & 1))) ++rounded;
    if (rounded >= (static_cast<unsigned __int128>(1) << 53)) return x * y;  // normal beyond 2*DBL_MIN
    return std::bit_cast<double>(sign | static_cast<std::uint64_t>(rounded));
}

inline bool is_subnormal(double x) { return x != 0.0 && std::abs(x) < DBL_MIN; }

// p + v*dt as the hardware would round it. For subnormal v and |p| >= 2^-900
// (with |dt| <= 2^30) the increment is below half an ulp of p, so p is the
// exact result and no subnormal is touched.
inline double advance(double p, double v, double dt) {
    if (is_subnormal(v)) {
        if (std::abs(p) >= 0x1p-900 && std::abs(dt) <= 0x1p30) return p;
        return p + exact_product_small(v, dt);
    }
    return p + v * dt;
}

// x*y exactly as the hardware would round it, fast for subnormal x.
inline double product(double x, double y) {
    return is_subnormal(x) ? exact_product_small(x, y) : x * y;
}

// x + y exactly as the hardware would round it, fast when x is subnormal and y
// is zero (a tangential velocity plus a zero gravity increment).
inline double sum(double x, double y) { return (y == 0.0 && is_subnormal(x)) ? x : x + y; }

// The least double h with h + reach >= size in round-to-nearest, for finite
// size and reach: rounding is monotone, so x + reach < size holds exactly
// when x < h. Found by bisection over the doubles in order (64 halvings).
inline double least_reaching(double size, double reach) {
    // Doubles in order as integers: -inf ... -0 = +0 ... +inf.
    auto key = [](double x) {
        const auto b = std::bit_cast<std::int64_t>(x);
        return b < 0 ? -(b & std::numeric_limits<std::int64_t>::max()) : b;
    };
    auto value = [](std::int64_t k) {
        return k < 0 ? -std::bit_cast<double>(-k) : std::bit_cast<double>(k);
    };
    constexpr double kInf = std::numeric_limits<double>::infinity();
    std::int64_t below = key(-kInf), reaching = key(kInf);  // -inf does not reach, +inf does
    while (reaching > below + 1) {
        const std::int64_t mid = std::midpoint(below, reaching);
        (value(mid) + reach >= size ? reaching : below) = mid;
    }
    return value(reaching);
}

}  // namespace detail

// The longest cycle of repeating states a consumer holds in memory to
// replay instead of stepping (reference/reference_simulator.cpp, the comparison's
// lockstep reference); a longer one is stepped to the end.
inline constexpr std::int64_t kMaxReplayedPeriod = 1 << 16;

// The document's model in D dimensions (2 or 3). Holds the model's own
// coordinates: the centre in 3D, the lower-left corner in 2D.
template <int D>
class ReferenceModel {
    static_assert(D == 2 || D == 3);

public:
    explicit ReferenceModel(const Scenario& s) : clock_(s.dt, s.duration) {
        const double r = s.radius;
        for (int i = 0; i < D; ++i) {
            q_[i] = (D == 2) ? s.position[i] - r : s.position[i];
            v_[i] = s.velocity[i];
            gdt_[i] = s.gravity[i] * s.dt;
            size_[i] = s.room[i];
            // The clamp values of EulersPosition: boundsMax - 2r (2D), boundsMax - r (3D).
            upper_clamp_[i] = (D == 2) ? s.room[i] - 2 * r : s.room[i] - r;
        }
        dt_ = s.dt;
        r_ = s.radius;
        two_r_ = 2 * r;
        alpha_ = s.alpha;
        tangential_factor_ = (s.alpha + s.beta) - s.alpha;
        careful_ = needs_care();
        // The in-bounds tests as single comparisons, for the free-flight loop.
        // q - r > 0 is q > r exactly (with gradual underflow a difference is
        // zero only for equal operands, and has the exact difference's sign).
        lower_limit_ = D == 2 ? 0.0 : r_;
        for (int i = 0; i < D; ++i) upper_limit_[i] = detail::least_reaching(size_[i], D == 2 ? two_r_ : r_);
    }

    bool running() const { return clock_.running(); }

    // One pass of the document's loop body, then t = t + dt.
    ContactMask step() {
        const ContactMask contact = move();
        clock_.advance();
        ++steps_;
        return contact;
    }

    // Takes every remaining step of the run; afterwards state() is the final
    // state, bit for bit what step() would have reached. Between contacts it
    // runs a free-flight loop with no per-step branch beyond one in-bounds
    // test; once the ball's state (position and velocity, not t) repeats one
    // seen at an earlier contact, the step map is periodic from there on, so
    // the remaining steps are counted on the clock alone and only their
    // remainder modulo the period is stepped.
    void run_to_end() {
        while (clock_.running()) {
            if (!careful_) {
                free_flight();
                if (!clock_.running()) break;
            }
            const ContactMask contact = move();
            clock_.advance();
            ++steps_;
            if (contact.any() && repeats_.seen(q_, v_, steps_)) {
                skip_periodic(steps_ - repeats_.match_step());
                return;
            }
        }
    }

    // step(), also watching for the state to repeat (as run_to_end does).
    // Once it has, the next repeat_period() states (at most
    // kMaxReplayedPeriod) are held with their contacts: from then on the
    // run repeats held_cycle(), bit for bit, to its end.
    ContactMask step_finding_period() {
        const ContactMask contact = step();
        if (repeat_period_ == 0) {
            if (contact.any() && repeats_.seen(q_, v_, steps_)) {
                repeat_found_at_ = steps_;
                repeat_period_ = steps_ - repeats_.match_step();
            }
        } else if (repeat_period_ <= kMaxReplayedPeriod && !cycle_held()) {
            held_cycle_.push_back(state());
            held_contacts_.push_back(contact);
        }
        return contact;
    }
    bool cycle_held() const {
        return repeat_period_ > 0 && static_cast<std::int64_t>(held_cycle_.size()) == repeat_period_;
    }
    const std::vector<State>& held_cycle() const { return held_cycle_; }
    const std::vector<ContactMask>& held_contacts() const { return held_contacts_; }

    // The steps left before the clock ends the run.
    std::int64_t remaining_steps() const { return clock_.remaining_steps(); }
    double dt() const { return dt_; }

    std::int64_t steps() const { return steps_; }
    // The step at which run_to_end() or step_finding_period() found the
    // state repeating, and the period in steps (0 if it never did).
    std::int64_t repeat_found_at() const { return repeat_found_at_; }
    std::int64_t repeat_period() const { return repeat_period_; }

    // step() up to `most` times while the ball flies free (no contact, not
    // on the careful path), with the centre after each step written to
    // out[0 ..]: the same bits as state().p after each, with the state kept
    // in registers rather than stored and reloaded each step. Returns the
    // steps taken (0 at a contact step, on the careful path, or at the end).
    std::int64_t free_flight_centres(std::int64_t most, Vec3* out) {
        if (careful_) return 0;
        return free_flight_steps(most, [&](std::int64_t n, const auto& q) {
            Vec3& p = out[n];
            for (int i = 0; i < 3; ++i) p[i] = i >= D ? 0.0 : (D == 2) ? q[i / 2][i % 2] + r_ : q[i / 2][i % 2];
        });
    }

    // The state in the scenario's terms: centre, velocity, time.
    State state() const {
        State s;
        s.t = clock_.t();
        for (int i = 0; i < D; ++i) {
            s.p[i] = (D == 2) ? q_[i] + r_ : q_[i];
            s.v[i] = v_[i];
        }
        return s;
    }

private:
    // The state part of a step (the clock is separate: the step map does not
    // depend on t). Subnormal velocities only appear late in the Zeno regime;
    // until then the plain hardware step is the exact one and needs no checks.
    ContactMask move() { return careful_ ? move_impl<true>() : move_impl<false>(); }

    // With Careful, products and sums that involve a subnormal operand go
    // through detail:: (same bits, no slow hardware path).
    template <bool Careful>
    ContactMask move_impl() {
        // EulersPosition: move with the old velocity, then clamp below and above.
        // Both in-bounds tests look at the unclamped position, as in the document.
        // A sum is -0 only if both terms are, and q is never -0, so the +0 of
        // the matrix products needs no extra operation here.
        for (int i = 0; i < D; ++i) {
            const double moved = Careful ? detail::advance(q_[i], v_[i], dt_) : q_[i] + v_[i] * dt_;
            double q = lower_in_bounds(moved) ? moved : lower_clamp();
            if (!upper_in_bounds(moved, i)) q = upper_clamp_[i];
            q_[i] = q;
        }
        // EulersVelocity: gravity, then the contact tests at the clamped position.
        ContactMask contact;
        for (int i = 0; i < D; ++i) {
            v_[i] = Careful ? detail::sum(v_[i], gdt_[i]) : v_[i] + gdt_[i];
            if (!lower_in_bounds(q_[i])) contact.lower |= 1u << i;
            if (!upper_in_bounds(q_[i], i)) contact.upper |= 1u << i;
        }
        if (contact.any()) {
            if (contact.lower) apply_damping<Careful>(contact.lower);
            if (contact.upper) apply_damping<Careful>(contact.upper);
            careful_ = needs_care();
        }
        return contact;
    }

    // Non-careful steps while the moved position stays inside every wall:
    // then the step is exactly q = q + v dt, v = v + g dt, with no clamp and
    // no contact. Stops before a step that would reach a wall (move() takes
    // that one) or at the end of the run. The components go two to a vector
    // (GCC/Clang vector extensions: each lane is the same IEEE operation as
    // the scalar code, so the same bits); a third component shares its pair
    // with a padding lane that never moves and is always inside.
    void free_flight() {
        free_flight_steps(std::numeric_limits<std::int64_t>::max(), [](std::int64_t, const auto&) {});
    }
    // At most `most` free-flight steps, with `each(n, q)` called after step
    // n with the position's pairs; returns the steps taken.
    template <class Each>
    std::int64_t free_flight_steps(std::int64_t most, Each&& each) {
        using Pair = double __attribute__((vector_size(16)));
        using PairMask = std::int64_t __attribute__((vector_size(16)));
        constexpr int kPairs = (D + 1) / 2;
        constexpr double kInf = std::numeric_limits<double>::infinity();
        // Pair k holds components 2k and 2k + 1 of x, or `pad` past D.
        auto pairs = [](auto x, double pad) {
            std::array<Pair, kPairs> out;
            for (int k = 0; k < kPairs; ++k) {
                const int i = 2 * k;
                out[k] = Pair{x(i), i + 1 < D ? x(i + 1) : pad};
            }
            return out;
        };
        std::array<Pair, kPairs> q = pairs([&](int i) { return q_[i]; }, 0.0);
        std::array<Pair, kPairs> v = pairs([&](int i) { return v_[i]; }, 0.0);
        const std::array<Pair, kPairs> g = pairs([&](int i) { return gdt_[i]; }, 0.0);
        const std::array<Pair, kPairs> lo = pairs([&](int) { return lower_limit_; }, -kInf);
        const std::array<Pair, kPairs> hi = pairs([&](int i) { return upper_limit_[i]; }, kInf);
        const Pair dt = {dt_, dt_};
        DocumentClock clock = clock_;
        std::int64_t n = 0;
        while (n < most && clock.running()) {
            std::array<Pair, kPairs> moved;
            PairMask inside = {-1, -1};
            for (int k = 0; k < kPairs; ++k) {
                moved[k] = q[k] + v[k] * dt;
                inside &= (moved[k] > lo[k]) & (moved[k] < hi[k]);
            }
            if ((inside[0] & inside[1]) == 0) break;
            for (int k = 0; k < kPairs; ++k) {
                q[k] = moved[k];
                v[k] = v[k] + g[k];
            }
            each(n, q);
            clock.advance();
            ++n;
        }
        for (int i = 0; i < D; ++i) {
            q_[i] = q[i / 2][i % 2];
            v_[i] = v[i / 2][i % 2];
        }
        clock_ = clock;
        steps_ += n;
        return n;
    }

    // The state has been seen `period` steps ago: from here the states repeat
    // with that period. The clock jumps to its end; the state steps only
    // the remainder.
    void skip_periodic(std::int64_t period) {
        repeat_found_at_ = steps_;
        repeat_period_ = period;
        const std::int64_t remaining = clock_.remaining_steps();
        clock_.advance(remaining);
        for (std::int64_t k = remaining % period; k > 0; --k) move();
        steps_ += remaining;
    }

    // Tells when the state after a contact equals the state after an earlier
    // contact, bit for bit: a state determines every later one, so that is a
    // cycle. Brent's way: one saved state, compared with each contact's,
    // replaced every kWindow contacts; a cycle of up to kWindow contacts is
    // found within 2 kWindow contacts of its start (the seed's rest repeats
    // every 30 steps, a few contacts). One hash compare per contact.
    class RepeatFinder {
    public:
        bool seen(const std::array<double, D>& q, const std::array<double, D>& v, std::int64_t step) {
            std::array<std::uint64_t, 2 * D> bits;
            for (int i = 0; i < D; ++i) {
                bits[i] = std::bit_cast<std::uint64_t>(q[i]);
                bits[D + i] = std::bit_cast<std::uint64_t>(v[i]);
            }
            std::uint64_t hash = 0;
            for (const std::uint64_t b : bits) hash = (hash ^ b) * 0x9E3779B97F4A7C15ull;
            if (contacts_ > 0 && hash == saved_hash_ && bits == saved_) return true;
            if (contacts_++ % kWindow == 0) {
                saved_ = bits;
                saved_hash_ = hash;
                saved_step_ = step;
            }
            return false;
        }
        // The step of the saved state that matched.
        std::int64_t match_step() const { return saved_step_; }

    private:
        static constexpr std::int64_t kWindow = 64;
        std::array<std::uint64_t, 2 * D> saved_{};
        std::uint64_t saved_hash_ = 0;
        std::int64_t saved_step_ = 0, contacts_ = 0;
    };

    // Whether a product or sum of this step could touch a subnormal. Only the
    // damping multiplications bring a velocity near that range (gravity adds
    // a normal increment), so this is re-evaluated after them only. Tiny means
    // below 2^-900: with |dt| and |g dt| at least 2^-100 and 2^-800 (else
    // always careful), no product or sum of normal operands above that is
    // subnormal.
    bool needs_care() const {
        auto tiny = [](double x, double below) { return x != 0.0 && std::abs(x) < below; };
        bool any = tiny(dt_, 0x1p-100);
        for (int i = 0; i < D; ++i) any |= tiny(v_[i], 0x1p-900) || tiny(gdt_[i], 0x1p-800);
        return any;
    }

    // The document's in-bounds tests, in its own arithmetic.
    bool lower_in_bounds(double q) const { return D == 2 ? q > 0.0 : q - r_ > 0.0; }
    bool upper_in_bounds(double q, int i) const {
        return D == 2 ? q + two_r_ < size_[i] : q + r_ < size_[i];
    }
    double lower_clamp() const { return D == 2 ? 0.0 : r_; }

    // out*(alpha+beta) - alpha on the diagonal: -alpha for a touched axis.
    // A zero product is +0 (`+ 0.0`), as the matrix product's sum from +0 gives.
    template <bool Careful>
    void apply_damping(std::uint8_t touched) {
        for (int i = 0; i < D; ++i) {
            const double factor = (touched >> i) & 1u ? -alpha_ : tangential_factor_;
            v_[i] = (Careful ? detail::product(v_[i], factor) : v_[i] * factor) + 0.0;
        }
    }

    DocumentClock clock_;
    std::array<double, D> q_{}, v_{}, gdt_{}, size_{}, upper_clamp_{};
    double dt_ = 0, r_ = 0, two_r_ = 0, alpha_ = 0, tangential_factor_ = 0;
    bool careful_ = false;  // take the subnormal-safe path (see needs_care)
    double lower_limit_ = 0;    // lower_in_bounds(q) is q > lower_limit_
    std::array<double, D> upper_limit_{};  // upper_in_bounds(q, i) is q < upper_limit_[i]
    std::int64_t steps_ = 0;  // steps taken, by step() or run_to_end()
    std::int64_t repeat_found_at_ = 0, repeat_period_ = 0;
    RepeatFinder repeats_;
    std::vector<State> held_cycle_;  // see step_finding_period
    std::vector<ContactMask> held_contacts_;
};

}  // namespace bouncecheck
