// libFuzzer target for the check that stands before merge's CBOR decoder
// (platform/cbor_check.h): cbor_problem must answer every input without
// crashing, and whatever it passes must decode without exhausting the stack
// (nlohmann's decoder recurses per level; a parse error is a fine answer).
// A crash or a sanitizer report is a finding.
#include "platform/cbor_check.h"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    if (bouncecheck::cbor_problem(bytes, 32)) return 0;
    try {
        (void)nlohmann::json::from_cbor(bytes);
    } catch (const nlohmann::json::exception&) {
        // Well-formed CBOR nlohmann does not take (a text string that is not UTF-8, say): refused, not a crash.
    }
    return 0;
}
