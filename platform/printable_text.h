// Text from outside (an external program's stderr, header and settings, a
// file's line) made safe to show anywhere: the terminal, report.md, JSON and
// HTML. Bytes that are not UTF-8 become U+FFFD, so no JSON writer refuses
// the report; control characters become visible escapes (ESC as "\x1b"),
// so none clears a terminal or breaks a Markdown table.
#pragma once

#include <exception>
#include <string>
#include <string_view>

namespace bouncecheck {

// `text` with every byte that is not part of a well-formed UTF-8 sequence
// replaced by U+FFFD, and every control character (C0, DEL, and C1 as code
// points) written as \xNN, tab included; a line break too, unless
// `keep_newlines`.
std::string printable_text(std::string_view text, bool keep_newlines = false);

// An exception's message as a user should read it: printable, and a JSON
// library error without its "[json.exception.parse_error.101] " prefix
// (what follows says where and why).
std::string error_text(const std::exception& e);

}  // namespace bouncecheck
