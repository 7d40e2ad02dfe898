#include "platform/printable_text.h"

#include <fmt/format.h>

namespace bouncecheck {

namespace {

// The length of the well-formed UTF-8 sequence at the start of `s` (RFC 3629:
// no overlong form, no surrogate, nothing above U+10FFFF), or 0.
std::size_t utf8_sequence(std::string_view s, char32_t& code) {
    const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
    const unsigned char b0 = byte(0);
    if (b0 < 0x80) {
        code = b0;
        return 1;
    }
    std::size_t n = 0;
    char32_t min = 0;
    if ((b0 & 0xE0) == 0xC0) n = 2, code = b0 & 0x1F, min = 0x80;
    else if ((b0 & 0xF0) == 0xE0) n = 3, code = b0 & 0x0F, min = 0x800;
    else if ((b0 & 0xF8) == 0xF0) n = 4, code = b0 & 0x07, min = 0x10000;
    else return 0;
    if (s.size() < n) return 0;
    for (std::size_t i = 1; i < n; ++i) {
        if ((byte(i) & 0xC0) != 0x80) return 0;
        code = (code << 6) | (byte(i) & 0x3F);
    }
    if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
    return n;
}

}  // namespace

std::string printable_text(std::string_view text, bool keep_newlines) {
    std::string out;
    out.reserve(text.size());
    while (!text.empty()) {
        char32_t code = 0;
        const std::size_t n = utf8_sequence(text, code);
        if (n == 0) {
            out += "\xEF\xBF\xBD";  // U+FFFD for the one byte that starts no sequence
            text.remove_prefix(1);
            continue;
        }
        if (code == '\n' && keep_newlines) out += '\n';
        else if (code < 0x20 || code == 0x7F || (code >= 0x80 && code < 0xA0)) out += fmt::format("\\x{:02x}", static_cast<unsigned>(code));
        else out.append(text.substr(0, n));
        text.remove_prefix(n);
    }
    return out;
}

std::string error_text(const std::exception& e) {
    std::string_view what = e.what();
    if (what.starts_with("[json.exception.")) {
        const auto end = what.find("] ");
        if (end != std::string_view::npos) what.remove_prefix(end + 2);
    }
    return printable_text(what);
}

}  // namespace bouncecheck
