// libFuzzer target for an external program's settings file
// (parse_external_settings, external/external_simulator.h): a JSON array of
// {key, value, why} the program writes, shown on the terminal and in every
// report. A refusal is a std::runtime_error (that class itself); an accepted
// file gives settings whose every string is what printable_text promises
// (well-formed UTF-8, no control character: C0, DEL or C1) and whose key is
// not empty. Another exception, a crash or a sanitizer report is a finding.
#include "external/external_simulator.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>
#include <typeinfo>

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_external_settings: %s\n%s\n", what, detail.c_str());
    std::abort();
}

// The first code point of `s` if it starts with a well-formed UTF-8 sequence
// (RFC 3629: shortest form, no surrogate, at most U+10FFFF), with its length.
std::size_t utf8_sequence(std::string_view s, char32_t& code) {
    const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
    std::size_t n = 0;
    char32_t min = 0;
    if (byte(0) < 0x80) n = 1, code = byte(0);
    else if ((byte(0) & 0xE0) == 0xC0) n = 2, code = byte(0) & 0x1F, min = 0x80;
    else if ((byte(0) & 0xF0) == 0xE0) n = 3, code = byte(0) & 0x0F, min = 0x800;
    else if ((byte(0) & 0xF8) == 0xF0) n = 4, code = byte(0) & 0x07, min = 0x10000;
    else return 0;
    if (s.size() < n) return 0;
    for (std::size_t i = 1; i < n; ++i) {
        if ((byte(i) & 0xC0) != 0x80) return 0;
        code = (code << 6) | (byte(i) & 0x3F);
    }
    if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
    return n;
}

void check_printable(const char* part, const std::string& text) {
    for (std::string_view rest = text; !rest.empty();) {
        char32_t code = 0;
        const std::size_t n = utf8_sequence(rest, code);
        if (n == 0) finding("a setting string that is not UTF-8", std::string(part) + ": " + text);
        if (code < 0x20 || code == 0x7F || (code >= 0x80 && code < 0xA0))
            finding("a setting string with a control character", std::string(part) + ": " + text);
        rest.remove_prefix(n);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        for (const bouncecheck::Setting& s : bouncecheck::parse_external_settings(text)) {
            if (s.key.empty()) finding("accepted a setting without a key", s.value);
            check_printable("key", s.key);
            check_printable("value", s.value);
            check_printable("why", s.why);
        }
    } catch (const std::runtime_error& e) {
        // A refusal: the run fails with "its settings file: <what>". Exactly
        // std::runtime_error: one derived from it (fmt::format_error) is a fault, not a refusal.
        if (typeid(e) != typeid(std::runtime_error))
            finding("an exception derived from std::runtime_error escaped",
                    std::string(typeid(e).name()) + ": " + e.what());
        if (std::string_view(e.what()).empty()) finding("a refusal without a reason", "");
    } catch (const std::exception& e) {
        finding("an exception other than std::runtime_error escaped", std::string(typeid(e).name()) + ": " + e.what());
    }
    return 0;
}
