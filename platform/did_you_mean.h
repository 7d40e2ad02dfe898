// "Did you mean": the known name closest to a mistyped one, for every
// message that refuses a name (scenario keys, engines, simulators, stress
// rows, command-line flags and commands).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

// The candidate closest to `word` by edit distance (insertions, deletions,
// substitutions and swaps of neighbours, ignoring case), if it is close enough
// to be a typo of it: at most one edit per three characters, and at least one.
// The first of equally close candidates.
std::optional<std::string> closest_name(std::string_view word, const std::vector<std::string>& candidates);

// "; did you mean 'x'?" with the closest candidate, or nothing.
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace bouncecheck
