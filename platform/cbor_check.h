// A CBOR document checked before it is decoded. nlohmann's from_cbor
// recurses once per nesting level, so a 150 KB file of nested arrays
// overflows the stack (merge crashed on one); this walk is iterative and
// refuses such a file first, saying where.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace bouncecheck {

// Why `bytes` is not exactly one well-formed CBOR data item (RFC 8949)
// nested at most `max_depth` deep, or nothing. Arrays, maps, tags and
// indefinite-length strings each count one level. Counts that the bytes
// left cannot hold are refused too (an array of 2^62 items in 20 bytes).
std::optional<std::string> cbor_problem(std::string_view bytes, std::size_t max_depth);

}  // namespace bouncecheck
