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

#include "adapters/state.h"
#include "reference/document_clock.h"
#include "scenarios/scenario.h"

#include <array>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>

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

}  // namespace detail

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
    }

    bool running() const { return clock_.running(); }

    // One pass of the document's loop body, then t = t + dt.
    ContactMask step() {
        // Subnormal velocities only appear late in the Zeno regime; until then
        // the plain hardware step is the exact one and needs no checks.
        return careful_ ? step_impl<true>() : step_impl<false>();
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
    // With Careful, products and sums that involve a subnormal operand go
    // through detail:: (same bits, no slow hardware path).
    template <bool Careful>
    ContactMask step_impl() {
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
        clock_.advance();
        return contact;
    }

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
};

}  // namespace bouncecheck
