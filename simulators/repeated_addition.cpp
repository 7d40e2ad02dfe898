#include "simulators/repeated_addition.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bouncecheck {

namespace {

// The binade a finite s >= 0 lies in, and its unit 2^unit_exponent. The
// subnormals (and 0) form one binade of their own, with the first normal
// binade's unit.
struct Binade {
    explicit Binade(double s) {
        if (s < std::numeric_limits<double>::min()) {
            id = std::numeric_limits<double>::min_exponent - 2;
            unit_exponent = std::numeric_limits<double>::min_exponent - 1 - 52;  // 2^-1074
            top_units = std::int64_t{1} << 52;                                  // the least normal
        } else {
            id = std::ilogb(s);
            unit_exponent = id - 52;
            top_units = std::int64_t{1} << 53;  // 2^(e+1)
        }
    }
    // s in units (exact: a power-of-two scaling of a whole number of units).
    std::int64_t units(double s) const { return static_cast<std::int64_t>(std::ldexp(s, -unit_exponent)); }
    double value(std::int64_t units) const { return std::ldexp(static_cast<double>(units), unit_exponent); }
    int id, unit_exponent;
    std::int64_t top_units;
};

bool fast_path_holds(double s, std::span<const double> cycle) {
    if (!(s >= 0) || !std::isfinite(s)) return false;
    return std::all_of(cycle.begin(), cycle.end(), [](double x) { return x >= 0 && std::isfinite(x); });
}

}  // namespace

double sum_after(double s, std::span<const double> cycle, std::size_t phase, std::int64_t n) {
    if (n <= 0 || cycle.empty()) return s;
    const std::size_t size = cycle.size();
    const auto period = static_cast<std::int64_t>(size);
    phase %= size;
    auto add = [&](std::int64_t count) {
        for (; count > 0; --count) {
            s = s + cycle[phase];
            if (++phase == size) phase = 0;
        }
    };
    if (!fast_path_holds(s, cycle)) {
        add(n);
        return s;
    }
    // Whole cycles, stepped until two in a row stay within one binade; the
    // second one's increment (in units) then holds for every later whole
    // cycle in that binade, and those are jumped.
    bool previous_within = false;
    while (n >= period) {
        const double before = s;
        add(period);
        n -= period;
        const Binade binade(before);
        const bool within = Binade(s).id == binade.id;
        if (within && previous_within) {
            const std::int64_t at = binade.units(s), increment = at - binade.units(before);
            std::int64_t cycles = n / period;
            if (increment > 0) cycles = std::min(cycles, (binade.top_units - 1 - at) / increment);
            s = binade.value(at + cycles * increment);
            n -= cycles * period;
            previous_within = false;
        } else {
            previous_within = within;
        }
    }
    add(n);
    return s;
}

std::optional<std::int64_t> additions_to_reach(double s, double step, double limit, std::int64_t at_most) {
    std::int64_t count = 0;
    if (!(s < limit)) return count;
    if (!(step > 0) || !fast_path_holds(s, {&step, 1})) {
        // One by one, while s still moves.
        for (double before = s; s < limit; before = s) {
            s = s + step;
            if (++count > at_most || s == before) return std::nullopt;
        }
        return count;
    }
    bool previous_within = false;
    while (true) {
        const double before = s;
        s = s + step;
        if (++count > at_most) return std::nullopt;
        if (!(s < limit)) return count;
        const Binade binade(before);
        const bool within = Binade(s).id == binade.id;
        if (!(within && previous_within)) {
            previous_within = within;
            continue;
        }
        const std::int64_t at = binade.units(s), increment = at - binade.units(before);
        if (increment == 0) return std::nullopt;
        const double top = binade.value(binade.top_units);  // may be infinite
        if (limit < top) {
            // The first sum at or beyond the limit, in whole units: if it
            // would cross the top, the crossing addition rounds to >= top anyway.
            const auto limit_units = static_cast<std::int64_t>(std::ceil(std::ldexp(limit, -binade.unit_exponent)));
            const std::int64_t more = (limit_units - at + increment - 1) / increment;
            if (more > at_most - count) return std::nullopt;
            return count + more;
        }
        const std::int64_t more = (binade.top_units - 1 - at) / increment;
        if (more > at_most - count) return std::nullopt;
        s = binade.value(at + more * increment);
        count += more;
        previous_within = false;
    }
}

}  // namespace bouncecheck
