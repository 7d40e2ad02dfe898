// A floating-point sum that adds the same values over and over (the
// document's clock t = t + dt; a running sum over a periodic tail), computed
// without doing every addition, bit for bit what the additions give.
//
// Why it has a closed form: a double s >= 0 is a whole number of units u =
// ulp(s) of its binade [2^e, 2^(e+1)), and so is the rounded s + x while it
// stays in that binade: the addition adds x rounded to a whole number of
// units, the same number at every addition, except for a tie (x half-way
// between two units), which rounds to the even sum. After one tie the sum is
// even, so from the second whole cycle within a binade on every cycle adds
// the same whole number of units. A binade is crossed in three stepped
// cycles and one multiplication, and a sum crosses at most a few dozen.
#pragma once

#include <cstdint>
#include <optional>
#include <span>

namespace bouncecheck {

// s after n additions s = s + cycle[(phase + k) % cycle.size()], k = 0 .. n-1,
// rounded as the loop rounds. O(cycle.size() x binades crossed) when s and
// every value are finite and >= 0; otherwise the additions are done one by one.
double sum_after(double s, std::span<const double> cycle, std::size_t phase, std::int64_t n);
inline double sum_after(double s, double step, std::int64_t n) { return sum_after(s, {&step, 1}, 0, n); }

// How many additions s = s + step it takes until s >= limit (0 if it already
// is), or nothing if that is more than `at_most` (or never: s stops growing).
// O(binades crossed) when s and step are finite, s >= 0 and step > 0;
// otherwise one by one.
std::optional<std::int64_t> additions_to_reach(double s, double step, double limit, std::int64_t at_most);

}  // namespace bouncecheck
