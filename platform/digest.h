// FNV-1a, 64 bits: the digest bouncecheck puts beside what it reads back
// (an output folder's manifest, a shard's results), to notice a file that
// changed or was corrupted since it was written. Not a defence against
// anyone who means it harm: a check against accidents.
#pragma once

#include <cstdint>
#include <string_view>

namespace bouncecheck {

class Fnv1a64 {
public:
    Fnv1a64& add(std::string_view bytes) {
        for (const char c : bytes) hash_ = (hash_ ^ static_cast<unsigned char>(c)) * 1099511628211ull;
        return *this;
    }
    std::uint64_t value() const { return hash_; }

private:
    std::uint64_t hash_ = 1469598103934665603ull;
};

}  // namespace bouncecheck
