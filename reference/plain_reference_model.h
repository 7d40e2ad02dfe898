// The document's 3D model transcribed plainly, with hardware arithmetic
// throughout: the oracle the fast ReferenceModel is checked against bit for
// bit (tests) and the baseline it is benchmarked against (bench). Not used to
// produce results.
#pragma once

#include "scenarios/scenario.h"

#include <array>

namespace bouncecheck {

struct PlainReferenceModel3d {
    explicit PlainReferenceModel3d(const Scenario& s)
        : p{s.position[0], s.position[1], s.position[2]},
          v{s.velocity[0], s.velocity[1], s.velocity[2]},
          s(s),
          tangential_factor((s.alpha + s.beta) - s.alpha) {}

    void step() {
        const double r = s.radius;
        unsigned lower = 0, upper = 0;
        for (int i = 0; i < 3; ++i) {
            const double moved = p[i] + v[i] * s.dt;
            double q = (moved - r > 0.0) ? moved : r;
            if (!(moved + r < s.room[i])) q = s.room[i] - r;
            p[i] = q + 0.0;
        }
        for (int i = 0; i < 3; ++i) {
            v[i] = v[i] + s.gravity[i] * s.dt;
            if (!(p[i] - r > 0.0)) lower |= 1u << i;
            if (!(p[i] + r < s.room[i])) upper |= 1u << i;
        }
        for (unsigned mask : {lower, upper})
            if (mask)
                for (int i = 0; i < 3; ++i) v[i] = v[i] * (((mask >> i) & 1u) ? -s.alpha : tangential_factor) + 0.0;
    }

    std::array<double, 3> p, v;
    Scenario s;
    double tangential_factor;
};

}  // namespace bouncecheck
