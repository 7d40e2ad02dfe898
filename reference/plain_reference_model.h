// The document's model transcribed plainly, with hardware arithmetic
// throughout: the oracle the fast ReferenceModel is checked against bit for
// bit (tests) and the baseline it is benchmarked against (bench). Not used to
// produce results.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/state.h"

#include <array>

namespace bouncecheck {

// D = 3 keeps the centre and tests p - r > 0, p + r < size; D = 2 keeps the
// lower-left corner q = centre - r and tests q > 0, q + 2r < size, as the
// document's 2D code does.
template <int D>
struct PlainReferenceModel {
    explicit PlainReferenceModel(const Scenario& s) : s(s), tangential_factor((s.alpha + s.beta) - s.alpha) {
        for (int i = 0; i < D; ++i) {
            p[i] = D == 2 ? s.position[i] - s.radius : s.position[i];
            v[i] = s.velocity[i];
        }
    }

    void step() {
        const double r = s.radius;
        const double low = D == 2 ? 0.0 : r;         // clamp below
        const double reach = D == 2 ? 2 * r : r;      // q + reach < size
        unsigned lower = 0, upper = 0;
        for (int i = 0; i < D; ++i) {
            const double moved = p[i] + v[i] * s.dt;
            const bool low_ok = D == 2 ? moved > 0.0 : moved - r > 0.0;
            double q = low_ok ? moved : low;
            if (!(moved + reach < s.room[i])) q = s.room[i] - reach;
            p[i] = q + 0.0;
        }
        for (int i = 0; i < D; ++i) {
            v[i] = v[i] + s.gravity[i] * s.dt;
            if (!(D == 2 ? p[i] > 0.0 : p[i] - r > 0.0)) lower |= 1u << i;
            if (!(p[i] + reach < s.room[i])) upper |= 1u << i;
        }
        for (unsigned mask : {lower, upper})
            if (mask)
                for (int i = 0; i < D; ++i) v[i] = v[i] * (((mask >> i) & 1u) ? -s.alpha : tangential_factor) + 0.0;
    }

    // Centre and velocity in the scenario's terms (t is the caller's clock).
    State state(double t) const {
        State out;
        out.t = t;
        for (int i = 0; i < D; ++i) {
            out.p[i] = D == 2 ? p[i] + s.radius : p[i];
            out.v[i] = v[i];
        }
        return out;
    }

    std::array<double, D> p, v;
    Scenario s;
    double tangential_factor;
};

using PlainReferenceModel3d = PlainReferenceModel<3>;

}  // namespace bouncecheck
