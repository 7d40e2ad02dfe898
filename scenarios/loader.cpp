#include "scenarios/loader.h"

#include "platform/did_you_mean.h"
#include "platform/program.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

// toml++ asserts, rather than reports, on some malformed input such as "[[[".
// Debian's libtomlplusplus, which the build links, has assertions off and
// reports a parse error there; keep that behaviour when the parser is compiled
// into this file instead (header-only builds), rather than aborting.
#if !defined(NDEBUG) && !defined(TOML_ASSERT)
#define TOML_ASSERT(expr) static_assert(true)
#endif
#include <toml++/toml.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>

namespace bouncecheck {

std::string Diagnostic::format() const {
    std::string out = file;
    if (line > 0) {
        out += fmt::format("{}{}", out.empty() ? "" : ":", line);
        if (column > 0) out += fmt::format(":{}", column);
    }
    for (const std::string* part : {&key, &reason}) {
        if (part->empty()) continue;
        if (!out.empty()) out += ": ";
        out += *part;
    }
    return out;
}

namespace {

std::string join_formatted(const std::vector<Diagnostic>& diagnostics) {
    std::string out;
    for (const Diagnostic& d : diagnostics) {
        if (!out.empty()) out += '\n';
        out += d.format();
    }
    return out;
}

}  // namespace

ScenarioError::ScenarioError(std::vector<Diagnostic> d)
    : std::runtime_error(join_formatted(d)), diagnostics_(std::move(d)) {}

namespace {

// Limits on untrusted input. A real scenario is well under 1 KiB, has a few
// dozen '.' and values of everyday magnitude, so none of these ever bites.
constexpr std::size_t kMaxInputBytes = std::size_t{1} << 20;
constexpr int kMaxDotsOutsideStrings = 1000;
// Also the range in which every integer converts to double exactly.
constexpr double kMaxMagnitude = 1e15;
// The engines abort on some input far below everyday scales, so the loader
// refuses it first: a 2D ball of radius 1e-100 makes Box2D assert (it scales
// lengths by 1/radius into floats, and speeds overflow), one of 1e-300 makes
// ODE abort (its inertia underflows), and so does a dt of 1e-300 at speeds of
// 1e15 or a subnormal dt (its constraint forces scale with 1/dt and overflow;
// its quaternion normalisation faults). With |v| <= kMaxMagnitude and these
// floors, every engine tried stays finite or fails cleanly.
constexpr double kMinRadius = 1e-9;
constexpr std::size_t kMaxNameBytes = 255;  // NAME_MAX: the name becomes a folder
constexpr std::size_t kMaxEchoBytes = 60;   // of untrusted text quoted in a reason

constexpr std::array<const char*, 3> kAxisNames{"x", "y", "z"};

bool is_ascii(char c) { return static_cast<unsigned char>(c) < 0x80; }
bool is_utf8_continuation(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }
bool is_ascii_alnum(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'); }
bool is_bare_key_char(char c) { return is_ascii_alnum(c) || c == '_' || c == '-'; }
bool is_name_char(char c) { return is_bare_key_char(c) || c == '.'; }

// Control characters escaped (so a reason stays on one line), and the bytes
// in `also` preceded by a backslash.
std::string escaped(std::string_view s, std::string_view also = {}) {
    std::string out;
    for (const char ch : s) {
        const auto c = static_cast<unsigned char>(ch);
        if (c < 0x20 || c == 0x7F) {
            out += fmt::format("\\u{:04X}", c);
        } else {
            if (also.find(ch) != std::string_view::npos) out += '\\';
            out += ch;
        }
    }
    return out;
}

// Untrusted text (keys, names) made safe to quote: escaped like a TOML basic
// string, and cut at a character boundary if long.
std::string printable(std::string_view s) {
    if (s.size() <= kMaxEchoBytes) return escaped(s, "\"\\");
    std::size_t cut = kMaxEchoBytes;
    while (cut > 0 && is_utf8_continuation(s[cut])) --cut;
    return escaped(s.substr(0, cut), "\"\\") + "...";
}

// Where a node or key starts; the document itself (no position) is 1:1.
template <typename Sourced>
toml::source_position start_of(const Sourced& sourced) {
    const toml::source_position begin = sourced.source().begin;
    return begin.line > 0 ? begin : toml::source_position{1, 1};
}

// Extends a dotted key path by one key, quoted as TOML would need it.
std::string child_key(std::string_view path, std::string_view key) {
    const bool bare = !key.empty() && std::all_of(key.begin(), key.end(), is_bare_key_char);
    std::string part = bare ? std::string(key) : fmt::format("\"{}\"", printable(key));
    return path.empty() ? part : fmt::format("{}.{}", path, part);
}

const char* type_name(const toml::node& node) {
    switch (node.type()) {
        case toml::node_type::string: return "a string";
        case toml::node_type::integer: return "an integer";
        case toml::node_type::floating_point: return "a floating-point number";
        case toml::node_type::boolean: return "a boolean";
        case toml::node_type::date: return "a date";
        case toml::node_type::time: return "a time";
        case toml::node_type::date_time: return "a date-time";
        case toml::node_type::array: return "an array";
        case toml::node_type::table: return "a table";
        case toml::node_type::none: break;
    }
    return "nothing";
}

constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

// Length of the well-formed UTF-8 sequence at text[i] (RFC 3629: no overlong
// forms, surrogates or code points past U+10FFFF), or 0 if it is malformed.
std::size_t utf8_length(std::string_view text, std::size_t i) {
    const auto byte = [&](std::size_t k) { return i + k < text.size() ? static_cast<unsigned char>(text[i + k]) : 0u; };
    const unsigned lead = byte(0);
    std::size_t length = 0;
    unsigned low = 0x80, high = 0xBF;  // the range allowed for the second byte
    if (lead < 0x80) return 1;
    if (lead >= 0xC2 && lead <= 0xDF) {
        length = 2;
    } else if (lead >= 0xE0 && lead <= 0xEF) {
        length = 3;
        if (lead == 0xE0) low = 0xA0;
        if (lead == 0xED) high = 0x9F;
    } else if (lead >= 0xF0 && lead <= 0xF4) {
        length = 4;
        if (lead == 0xF0) low = 0x90;
        if (lead == 0xF4) high = 0x8F;
    } else {
        return 0;
    }
    if (byte(1) < low || byte(1) > high) return 0;
    for (std::size_t k = 2; k < length; ++k) {
        if ((byte(k) & 0xC0) != 0x80) return 0;
    }
    return length;
}

// Input that toml++ 3.3 does not survive, found before it parses.
struct Hazard {
    toml::source_position where;
    std::string reason;
};

// Found by one scan that tells strings and comments apart. It follows TOML,
// so it is exact for valid TOML and for the prefix toml++ reads before its
// first error; past that it may be wrong, which each check allows for:
// - Deep key paths. toml++ recurses once per level of a table path (parsing,
//   and freeing the tree) and overflows the stack near 1e5 levels; arrays and
//   inline tables it caps at 256 itself. Each level of a path costs a '.'
//   outside strings and comments, so bounding those bounds the depth (dots in
//   floats count too, erring on the safe side). toml++ stops at the first
//   error, and the scan is exact up to there.
// - Non-ASCII characters where toml++'s whitespace test is undefined
//   behaviour (marzer/tomlplusplus#190): outside strings and comments, where
//   TOML allows none anyway, and after a backslash in a multi-line basic
//   string. The scan may miss some in invalid TOML: see ascii_stand_in.
// - Malformed UTF-8, so that ascii_stand_in can rely on it.
std::optional<Hazard> find_parser_hazard(std::string_view text) {
    toml::source_position pos{1, 1};
    std::size_t pos_index = 0;  // `pos` is the position of text[pos_index]
    const auto position_of = [&](std::size_t index) {
        for (; pos_index < index; ++pos_index) {
            if (text[pos_index] == '\n') {
                ++pos.line;
                pos.column = 1;
            } else if (!is_utf8_continuation(text[pos_index])) {
                ++pos.column;  // columns count characters, not UTF-8 continuation bytes
            }
        }
        return pos;
    };

    enum class State { code, comment, basic, literal, multiline_basic, multiline_literal };
    State state = State::code;
    int dots = 0;
    // A byte order mark is not part of the document (toml++ skips it too).
    for (std::size_t i = text.starts_with(kByteOrderMark) ? kByteOrderMark.size() : 0; i < text.size();) {
        const char c = text[i];
        std::size_t n = utf8_length(text, i);  // bytes this step consumes
        if (n == 0) return Hazard{position_of(i), "invalid UTF-8"};
        switch (state) {
            case State::code:
                if (!is_ascii(c)) {
                    return Hazard{position_of(i), "non-ASCII character outside a string or comment"};
                } else if (c == '#') {
                    state = State::comment;
                } else if (c == '"' || c == '\'') {
                    const bool multiline = text.substr(i, 3) == (c == '"' ? R"(""")" : "'''");
                    n = multiline ? 3 : 1;
                    if (c == '"') state = multiline ? State::multiline_basic : State::basic;
                    else state = multiline ? State::multiline_literal : State::literal;
                } else if (c == '.' && ++dots > kMaxDotsOutsideStrings) {
                    return Hazard{position_of(i),
                                  fmt::format("more than {} '.' outside strings and comments; refusing keys "
                                              "nested this deeply",
                                              kMaxDotsOutsideStrings)};
                }
                break;
            case State::comment:
                if (c == '\n') state = State::code;
                break;
            default: {
                const bool basic = state == State::basic || state == State::multiline_basic;
                const bool multiline = state == State::multiline_basic || state == State::multiline_literal;
                const char quote = basic ? '"' : '\'';
                if (basic && c == '\\') {
                    // An escape or a line-ending backslash: toml++ tests what follows any whitespace.
                    const std::size_t next = std::min(text.find_first_not_of(" \t\r\n", i + 1), text.size());
                    if (multiline && next < text.size() && !is_ascii(text[next]))
                        return Hazard{position_of(next),
                                      "non-ASCII character after a backslash in a multi-line string, which "
                                      "toml++ 3.3 cannot parse safely; start the line with an ASCII character"};
                    if (i + 1 < text.size() && is_ascii(text[i + 1])) n = 2;  // e.g. an escaped quote
                } else if (c == quote) {
                    // A multi-line string's closing quotes may follow up to two quotes of content.
                    if (multiline) n = std::min(text.find_first_not_of(quote, i), text.size()) - i;
                    if (!multiline || n >= 3) state = State::code;
                } else if (c == '\n' && !multiline) {
                    state = State::code;  // unterminated: a syntax error for toml++ anyway
                }
            }
        }
        i += n;
    }
    return std::nullopt;
}

// `text` (well-formed UTF-8) with each non-ASCII character replaced by '?'.
// TOML allows both only in strings and comments, so the copy is valid exactly
// when `text` is, with every token at the same line and column, and toml++
// parses it without reaching the undefined behaviour. Once the copy parses,
// the scan above was exact, and `text` itself is safe to parse.
std::string ascii_stand_in(std::string_view text) {
    const std::size_t bom = text.starts_with(kByteOrderMark) ? kByteOrderMark.size() : 0;
    std::string out(text.substr(0, bom));
    for (std::size_t i = bom; i < text.size(); i += std::max<std::size_t>(1, utf8_length(text, i)))
        out += is_ascii(text[i]) ? text[i] : '?';
    return out;
}

// A number read from the file, with where it came from for later range checks.
struct Number {
    double value;
    std::string key;
    toml::source_position where;
};

// An integer read from the file, likewise.
struct Integer {
    std::int64_t value;
    std::string key;
    toml::source_position where;
};

// Collects diagnostics while reading a parsed document. Every key it reads is
// marked used, so whatever is left over is reported as unknown at the end.
class Checker {
public:
    explicit Checker(std::string file) : file_(std::move(file)) {}

    void report(toml::source_position where, std::string key, std::string reason) {
        diagnostics_.push_back(
            {file_, static_cast<int>(where.line), static_cast<int>(where.column), std::move(key), std::move(reason)});
    }
    void expect(bool ok, const Number& n, std::string reason) {
        if (!ok) report(n.where, n.key, std::move(reason));
    }
    bool ok() const { return diagnostics_.empty(); }

    [[noreturn]] void fail() {
        std::stable_sort(diagnostics_.begin(), diagnostics_.end(), [](const Diagnostic& a, const Diagnostic& b) {
            return std::pair(a.line, a.column) < std::pair(b.line, b.column);
        });
        throw ScenarioError(std::move(diagnostics_));
    }

    // Looks up `key` in a table (the document if `path` is empty) and marks it used.
    const toml::node* get(const toml::table& table, std::string_view path, std::string_view key,
                          bool required = true, std::string_view missing = "missing required key") {
        watch(table, path);
        asked_[&table].emplace_back(key);
        const toml::node* node = table.get(key);
        if (node) used_.insert(node);
        else if (required) report(start_of(table), child_key(path, key), std::string(missing));
        return node;
    }

    // A required top-level table, or null (reported) if missing or not a table.
    const toml::table* table(const toml::table& root, std::string_view key) {
        const toml::node* node = get(root, "", key, true, fmt::format("missing required table [{}]", key));
        if (!node) return nullptr;
        const toml::table* t = node->as_table();
        if (!t) report(start_of(*node), std::string(key), fmt::format("expected a table, got {}", type_name(*node)));
        return t;
    }

    // A string value, or null (reported if present with another type, or required and missing).
    const toml::value<std::string>* string(const toml::table& table, std::string_view key, bool required,
                                           std::string_view path = "") {
        const toml::node* node = get(table, path, key, required);
        if (!node) return nullptr;
        const auto* s = node->as_string();
        if (!s)
            report(start_of(*node), child_key(path, key), fmt::format("expected a string, got {}", type_name(*node)));
        return s;
    }

    // An optional table inside `table`, or null (reported if present but not a table).
    const toml::table* optional_table(const toml::table& table, std::string_view path, std::string_view key) {
        const toml::node* node = get(table, path, key, false);
        if (!node) return nullptr;
        const toml::table* t = node->as_table();
        if (!t)
            report(start_of(*node), child_key(path, key), fmt::format("expected a table, got {}", type_name(*node)));
        return t;
    }

    // An optional number in `table`.
    std::optional<Number> optional_number(const toml::table& table, std::string_view path, std::string_view key) {
        const toml::node* node = get(table, path, key, false);
        if (!node) return std::nullopt;
        return check_number(*node, child_key(path, key));
    }

    // An optional integer in `table`; a floating-point value, even a whole one such as 5.0, is reported.
    std::optional<Integer> optional_integer(const toml::table& table, std::string_view path, std::string_view key) {
        const toml::node* node = get(table, path, key, false);
        if (!node) return std::nullopt;
        const auto* i = node->as_integer();
        if (!i) {
            report(start_of(*node), child_key(path, key), fmt::format("expected an integer, got {}", type_name(*node)));
            return std::nullopt;
        }
        return Integer{i->get(), child_key(path, key), start_of(*node)};
    }

    // Marks every key of `table` as looked at, so unknown ones are reported.
    void watch_table(const toml::table& table, std::string_view path) { watch(table, path); }

    // A required number in `table` (nothing is reported if the table itself is missing).
    std::optional<Number> number(const toml::table* table, std::string_view path, std::string_view key) {
        const toml::node* node = table ? get(*table, path, key) : nullptr;
        if (!node) return std::nullopt;
        return check_number(*node, child_key(path, key));
    }

    // A required array of numbers with `dim` elements, or 2 or 3 if `dim` is
    // 0. Empty unless every element is a valid number and the length is right.
    std::optional<std::vector<Number>> vector(const toml::table* table, std::string_view path, std::string_view key,
                                              int dim) {
        const toml::node* node = table ? get(*table, path, key) : nullptr;
        if (!node) return std::nullopt;
        const std::string name = child_key(path, key);
        const toml::array* array = node->as_array();
        if (!array) {
            report(start_of(*node), name, fmt::format("expected an array of numbers, got {}", type_name(*node)));
            return std::nullopt;
        }
        const std::size_t n = array->size();
        const bool length_ok = dim == 0 ? (n == 2 || n == 3) : n == static_cast<std::size_t>(dim);
        if (!length_ok) {
            report(start_of(*node), name,
                   dim == 0 ? fmt::format("expected an array of 2 or 3 numbers, got {} elements", n)
                            : fmt::format("expected {} numbers to match the dimension of room.size, got {}", dim, n));
        }
        // Elements of an array far too long are not worth a diagnostic each.
        if (n > 3) return std::nullopt;
        std::vector<Number> numbers;
        for (std::size_t i = 0; i < n; ++i) {
            if (auto number = check_number((*array)[i], fmt::format("{}[{}]", name, i)))
                numbers.push_back(std::move(*number));
        }
        if (!length_ok || numbers.size() != n) return std::nullopt;
        return numbers;
    }

    // Reports every key of a looked-at table that was never read.
    // Each with the closest key the table has, and the table's keys.
    void report_unknown_keys() {
        for (const auto& [table, path] : watched_) {
            std::vector<std::string> keys;  // every key the loader looks for in this table, as asked
            for (const std::string& key : asked_[table])
                if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
            for (const auto& [key, node] : *table) {
                if (used_.count(&node)) continue;
                std::string reason = "unknown key" + did_you_mean(key.str(), keys);
                if (!keys.empty())
                    reason += fmt::format(" (keys of {}: {})", path.empty() ? "the file" : "[" + path + "]",
                                          fmt::join(keys, ", "));
                report(start_of(key), child_key(path, key.str()), std::move(reason));
            }
        }
    }

private:
    // Integers are accepted where numbers are expected; the value is kept exactly as parsed.
    std::optional<Number> check_number(const toml::node& node, std::string key) {
        Number n{0.0, std::move(key), start_of(node)};
        if (const auto* f = node.as_floating_point()) n.value = f->get();
        else if (const auto* i = node.as_integer()) n.value = static_cast<double>(i->get());
        else {
            report(n.where, n.key, fmt::format("expected a number, got {}", type_name(node)));
            return std::nullopt;
        }
        if (!std::isfinite(n.value)) {
            report(n.where, n.key, fmt::format("must be a finite number, got {}", n.value));
            return std::nullopt;
        }
        if (std::abs(n.value) > kMaxMagnitude) {
            report(n.where, n.key, fmt::format("magnitude of {} exceeds the limit of {}", n.value, kMaxMagnitude));
            return std::nullopt;
        }
        return n;
    }

    void watch(const toml::table& table, std::string_view path) {
        const bool known = std::any_of(watched_.begin(), watched_.end(),
                                       [&](const auto& watched) { return watched.first == &table; });
        if (!known) watched_.emplace_back(&table, std::string(path));
    }

    std::string file_;
    std::vector<Diagnostic> diagnostics_;
    std::set<const toml::node*> used_;
    std::vector<std::pair<const toml::table*, std::string>> watched_;
    std::map<const toml::table*, std::vector<std::string>> asked_;  // the keys looked up, per table
};

// Parses with toml++, turning its error into a diagnostic.
toml::table parse_toml(std::string_view text, Checker& c, const std::string& file_name) {
    try {
        return toml::parse(text, std::string_view{file_name});
    } catch (const toml::parse_error& e) {
        c.report(e.source().begin, "", escaped(e.description()));  // it may quote a raw newline
        c.fail();
    }
}

void check_name(Checker& c, const toml::value<std::string>& node) {
    if (auto problem = name_problem(node.get())) c.report(start_of(node), "name", std::move(*problem));
}

Vec3 to_vec3(const std::vector<Number>& numbers) {
    Vec3 v = Vec3::Zero();  // the unused third component of a 2D scenario stays 0
    for (std::size_t i = 0; i < numbers.size(); ++i) v[static_cast<Eigen::Index>(i)] = numbers[i].value;
    return v;
}

constexpr std::int64_t kMaxSubsteps = 1000;

// ccd and substeps of an [engines.<name>] table: the remedies for fast balls
// and large steps (see docs/engines.md for what each engine does with them).
void read_collision_options(const toml::table& engine, const std::string& path, const std::string& name,
                            EngineOptions& options, Checker& c) {
    if (const toml::node* node = c.get(engine, path, "ccd", false)) {
        if (const auto* flag = node->as_boolean()) {
            options.ccd = flag->get();
            static constexpr std::array<std::pair<std::string_view, std::string_view>, 7> kWithoutCcd{
                {{"ode", "ODE"},
                 {"mujoco", "MuJoCo"},
                 {"mujoco3", "MuJoCo"},
                 {"chipmunk", "Chipmunk"},
                 {"siconos", "Siconos"},
                 {"siconos-ed", "Siconos"},
                 {"dart", "DART"}}};
            for (const auto& [engine, display] : kWithoutCcd)
                if (name == engine && flag->get())
                    c.report(start_of(*node), child_key(path, "ccd"),
                             fmt::format("{} has no continuous collision detection; use substeps instead", display));
        } else {
            c.report(start_of(*node), child_key(path, "ccd"), fmt::format("expected a boolean, got {}", type_name(*node)));
        }
    }
    if (const auto n = c.optional_integer(engine, path, "substeps")) {
        if (n->value >= 1 && n->value <= kMaxSubsteps) options.substeps = static_cast<int>(n->value);
        else c.report(n->where, n->key, fmt::format("must be within [1, {}], got {}", kMaxSubsteps, n->value));
    }
}

// The names a file may give [engines.<name>] and [thresholds.<name>]
// tables: the built-in simulators, and the external ones declared in the
// file or on the command line.
struct KnownNames {
    std::set<std::string> externals;
    bool engine(std::string_view name) const {
        const auto engines = built_in_engines();
        return std::find(engines.begin(), engines.end(), name) != engines.end() || external(name);
    }
    bool simulator(std::string_view name) const {
        return std::find(kBuiltInSimulators.begin(), kBuiltInSimulators.end(), name) != kBuiltInSimulators.end() ||
               external(name);
    }
    bool external(std::string_view name) const { return externals.count(std::string(name)) > 0; }
    std::vector<std::string> names(std::span<const std::string_view> built_in) const {
        std::vector<std::string> out(built_in.begin(), built_in.end());
        out.insert(out.end(), externals.begin(), externals.end());
        return out;
    }
    std::string list(std::span<const std::string_view> built_in) const {
        return fmt::format("{}", fmt::join(names(built_in), ", "));
    }
    // Why `name` is refused, with the closest known name: a name none is
    // close to is most likely a simulator from outside the build, not declared.
    std::string unknown(std::string_view what, std::string_view name, std::span<const std::string_view> built_in) const {
        const auto close = closest_name(name, names(built_in));
        if (close) return fmt::format("unknown {}; did you mean '{}'? (known: {})", what, *close, list(built_in));
        return fmt::format("unknown {} (known: {}); a simulator from outside the build is declared with "
                           "--external {}=COMMAND or an [external.{}] table",
                           what, list(built_in), name, name);
    }
};

// A TOML table as JSON text (dates and times become strings), for an
// external simulator's [engines.<name>], which bouncecheck passes on unread.
std::string toml_to_json(const toml::table& table) {
    std::ostringstream out;
    out << toml::json_formatter{table};
    return out.str();
}

// [external.<name>]: an external simulator for this scenario (docs/external.md):
// `command`, the program and its arguments. A program path holding a '/' is
// relative to the file's folder; one without is looked up on PATH.
std::map<std::string, std::vector<std::string>> read_externals(const toml::table& root, Checker& c,
                                                               const std::filesystem::path& folder,
                                                               const std::vector<std::string>& declared_elsewhere) {
    std::map<std::string, std::vector<std::string>> externals;
    const toml::table* table = c.optional_table(root, "", "external");
    if (!table) return externals;
    for (const auto& [key, node] : *table) {
        const std::string name(key.str());
        const std::string path = child_key("external", name);
        // A bad name is reported and goes no further: it names nothing, and
        // is never quoted again unescaped.
        if (auto problem = name_problem(name)) {
            c.report(start_of(key), path, std::move(*problem));
            continue;
        }
        if (std::find(kBuiltInSimulators.begin(), kBuiltInSimulators.end(), name) != kBuiltInSimulators.end()) {
            c.report(start_of(key), path, fmt::format("'{}' is a built-in simulator's name", name));
            continue;
        }
        if (std::find(declared_elsewhere.begin(), declared_elsewhere.end(), name) != declared_elsewhere.end()) {
            c.report(start_of(key), path, fmt::format("'{}' is also declared by --external", name));
            continue;
        }
        const toml::table* external = c.optional_table(*table, "external", name);
        if (!external) continue;
        c.watch_table(*external, path);
        const toml::node* command = c.get(*external, path, "command");
        if (!command) continue;
        const toml::array* array = command->as_array();
        std::vector<std::string> argv;
        if (array)
            for (const toml::node& arg : *array)
                if (const auto* text = arg.as_string()) argv.push_back(text->get());
        if (!array || array->empty() || argv.size() != array->size()) {
            c.report(start_of(*command), child_key(path, "command"),
                     "expected a non-empty array of strings: the program, then its arguments");
            continue;
        }
        const bool has_path = argv[0].find('/') != std::string::npos;
        if (auto program = resolve_program(argv[0], folder)) {
            argv[0] = std::move(*program);
        } else {
            c.report(start_of(*command), child_key(path, "command"),
                     argv[0].empty() ? std::string("the program's name is empty")
                                     : fmt::format("cannot run the program \"{}\": {}", printable(argv[0]),
                                                   has_path ? "it is not an executable file (relative to this "
                                                              "file's folder)"
                                                            : "it is not found on PATH"));
        }
        externals[name] = std::move(argv);
    }
    return externals;
}

// [engines.<name>]: per-engine settings. Engine names are checked against
// every engine bouncecheck knows, built or not, so a file validates the same
// on every build, and the external simulators (`passthrough` gets their tables).
std::map<std::string, EngineOptions> read_engines(const toml::table& root, Checker& c, const KnownNames& known,
                                                  std::map<std::string, std::string>& passthrough) {
    std::map<std::string, EngineOptions> engines;
    const toml::table* table = c.optional_table(root, "", "engines");
    if (!table) return engines;
    for (const auto& [key, node] : *table) {
        const std::string name(key.str());
        const std::string path = child_key("engines", name);
        if (!known.engine(name)) continue;  // reported as unknown
        const toml::table* engine = c.optional_table(*table, "engines", name);
        if (!engine) continue;
        if (known.external(name)) {  // the program's own: passed on as written
            std::string text = toml_to_json(*engine);
            if (nlohmann::json::accept(text)) passthrough[name] = std::move(text);
            else c.report(start_of(*engine), path, "cannot be passed on as JSON");
            continue;
        }
        c.watch_table(*engine, path);
        if (is_hosted_engine(name)) {  // the engine's own keys: passed on as written
            toml::table own;
            for (const std::string_view key : hosted_engine_keys(name)) {
                const toml::node* node = c.get(*engine, path, key, false);
                if (!node) continue;
                const auto scalar = [](const toml::node& n) { return n.is_string() || n.is_number() || n.is_boolean(); };
                const toml::array* list = node->as_array();
                if (scalar(*node) || (list && std::all_of(list->begin(), list->end(), scalar)))
                    own.insert(key, *node);
                else
                    c.report(start_of(*node), child_key(path, key),
                             fmt::format("expected a string, a number, a boolean or an array of them, got {}",
                                         type_name(*node)));
            }
            if (!own.empty()) passthrough[name] = toml_to_json(own);
        }
        EngineOptions options;
        options.tangential_unset = !engine->contains("tangential_model") && !engine->contains("friction");
        if (const auto* model = c.string(*engine, "tangential_model", false, path)) {
            if (model->get() == "friction") options.tangential_model = TangentialModel::friction;
            else if (model->get() == "per-contact") options.tangential_model = TangentialModel::per_contact;
            else
                c.report(start_of(*model), child_key(path, "tangential_model"),
                         fmt::format("must be \"friction\" or \"per-contact\", got \"{}\"", printable(model->get())));
        }
        if (const auto mu = c.optional_number(*engine, path, "friction")) {
            c.expect(mu->value >= 0 && mu->value <= 10, *mu,
                     fmt::format("friction coefficient must be within [0, 10], got {}", mu->value));
            c.expect(options.tangential_model == TangentialModel::friction, *mu,
                     "friction applies only with tangential_model = \"friction\" (per-contact runs with mu = 0)");
            options.friction = mu->value;
        }
        if (const auto* rotation = c.string(*engine, "rotation", false, path)) {
            if (rotation->get() == "free") options.free_rotation = true;
            else if (rotation->get() == "locked") options.free_rotation = false;
            else
                c.report(start_of(*rotation), child_key(path, "rotation"),
                         fmt::format("must be \"free\" or \"locked\", got \"{}\"", printable(rotation->get())));
        }
        read_collision_options(*engine, path, name, options, c);
        engines[name] = options;
    }
    for (const auto& [key, node] : *table) {
        if (known.engine(key.str())) continue;
        c.report(start_of(key), child_key("engines", key.str()), known.unknown("engine", key.str(), built_in_engines()));
        c.get(*table, "engines", key.str(), false);  // reported here, not again as an unknown key
    }
    return engines;
}

// The keys of a threshold set: bounce_count, and the limits that are numbers >= 0.
constexpr std::string_view kBounceCountKey = "bounce_count";
constexpr std::int64_t kMaxBounceCount = 10000;
bool is_threshold_key(std::string_view key) {
    return key == kBounceCountKey || std::any_of(std::begin(kThresholdLimits), std::end(kThresholdLimits),
                                                 [&](const ThresholdLimit& limit) { return limit.key == key; });
}

// One threshold set: the table [thresholds] or [thresholds.<simulator>] at `path`.
// Every limit is optional; one left unset is not checked.
ThresholdSet read_threshold_set(const toml::table& table, const std::string& path, Checker& c) {
    ThresholdSet set;
    if (const auto count = c.optional_integer(table, path, kBounceCountKey)) {
        if (count->value >= 1 && count->value <= kMaxBounceCount) set.bounce_count = static_cast<int>(count->value);
        else
            c.report(count->where, count->key,
                     fmt::format("must be within [1, {}], got {}", kMaxBounceCount, count->value));
    }
    for (const auto& [key, member] : kThresholdLimits) {
        if (const auto limit = c.optional_number(table, path, key)) {
            c.expect(limit->value >= 0, *limit, fmt::format("must be >= 0, got {}", limit->value));
            set.*member = limit->value;
        }
    }
    return set;
}

// [thresholds] and [thresholds.<simulator>]: CI limits on each simulator's
// divergence from the reference, a simulator's table overriding the common
// one. Simulator names are checked against every simulator bouncecheck
// knows, built or not, so a file validates the same on every build.
Thresholds read_thresholds(const toml::table& root, Checker& c, const KnownNames& known) {
    Thresholds thresholds;
    const toml::table* table = c.optional_table(root, "", "thresholds");
    if (!table) return thresholds;
    c.watch_table(*table, "thresholds");
    thresholds.all = read_threshold_set(*table, "thresholds", c);
    for (const auto& [key, node] : *table) {
        const std::string name(key.str());
        if (!known.simulator(name)) continue;
        const toml::table* simulator = c.optional_table(*table, "thresholds", name);  // reported if not a table
        if (!simulator) continue;
        const std::string path = child_key("thresholds", name);
        c.watch_table(*simulator, path);
        thresholds.simulator[name] = read_threshold_set(*simulator, path, c);
    }
    // Any other table is meant for a simulator; any other value is an unknown key, reported at the end.
    for (const auto& [key, node] : *table) {
        if (!node.is_table() || is_threshold_key(key.str()) || known.simulator(key.str())) continue;
        c.report(start_of(key), child_key("thresholds", key.str()),
                 known.unknown("simulator", key.str(), kBuiltInSimulators));
        c.get(*table, "thresholds", key.str(), false);  // reported here, not again as an unknown key
    }
    return thresholds;
}

Scenario validate(const toml::table& root, Checker& c, const std::filesystem::path& folder,
                  const std::vector<std::string>& external_names) {
    const auto* name = c.string(root, "name", true);
    const auto* description = c.string(root, "description", false);
    if (name) check_name(c, *name);

    const toml::table* room = c.table(root, "room");
    const toml::table* ball = c.table(root, "ball");
    const toml::table* world = c.table(root, "world");
    const toml::table* damping = c.table(root, "damping");
    const toml::table* run = c.table(root, "run");

    // The dimension is room.size's; the other vectors are checked against it
    // (only against "2 or 3" if room.size is unusable).
    const auto size = c.vector(room, "room", "size", 0);
    const int dim = size ? static_cast<int>(size->size()) : 0;
    const auto radius = c.number(ball, "ball", "radius");
    const auto position = c.vector(ball, "ball", "position", dim);
    const auto velocity = c.vector(ball, "ball", "velocity", dim);
    const auto gravity = c.vector(world, "world", "gravity", dim);
    const auto alpha = c.number(damping, "damping", "normal");
    const auto beta = c.number(damping, "damping", "tangential");
    const auto dt = c.number(run, "run", "dt");
    const auto duration = c.number(run, "run", "duration");
    auto externals = read_externals(root, c, folder, external_names);
    KnownNames known;
    known.externals.insert(external_names.begin(), external_names.end());
    for (const auto& [external, command] : externals) known.externals.insert(external);
    std::map<std::string, std::string> passthrough;
    auto engines = read_engines(root, c, known, passthrough);
    auto thresholds = read_thresholds(root, c, known);
    c.report_unknown_keys();

    if (radius) {
        c.expect(radius->value > 0, *radius, fmt::format("must be > 0, got {}", radius->value));
        if (radius->value > 0)
            c.expect(radius->value >= kMinRadius, *radius,
                     fmt::format("{} m is below the limit of {} m (1 nm), which keeps every engine's arithmetic "
                                 "in range",
                                 radius->value, kMinRadius));
    }
    const bool radius_ok = radius && radius->value >= kMinRadius;
    if (size) {
        for (std::size_t i = 0; i < size->size(); ++i) {
            const Number& side = (*size)[i];
            if (radius_ok)
                c.expect(side.value > 2 * radius->value, side,
                         fmt::format("room side {} must be larger than the ball's diameter 2 x radius = {}",
                                     side.value, 2 * radius->value));
            else
                c.expect(side.value > 0, side, fmt::format("room side must be > 0, got {}", side.value));
        }
    }
    if (size && position && radius_ok) {
        for (std::size_t i = 0; i < position->size(); ++i) {
            const double side = (*size)[i].value, r = radius->value, p = (*position)[i].value;
            if (side <= 2 * r) continue;  // already reported: no position fits
            c.expect(r <= p && p <= side - r, (*position)[i],
                     fmt::format("ball starts outside the room: centre {} = {} must be within [radius, size - "
                                 "radius] = [{}, {}]",
                                 kAxisNames[i], p, r, side - r));
        }
    }
    for (const auto& factor : {alpha, beta}) {
        if (factor)
            c.expect(factor->value >= 0 && factor->value <= 1, *factor,
                     fmt::format("damping factor must be within [0, 1], got {}", factor->value));
    }
    if (dt) {
        c.expect(dt->value > 0, *dt, fmt::format("must be > 0, got {}", dt->value));
        if (dt->value > 0)
            c.expect(dt->value >= kMinDt, *dt,
                     fmt::format("{} s is below the limit of {} s (1 ns), which keeps every engine's arithmetic in "
                                 "range",
                                 dt->value, kMinDt));
    }
    if (duration)
        c.expect(duration->value > 0, *duration, fmt::format("must be > 0, got {}", duration->value));
    if (dt && duration && dt->value >= kMinDt && duration->value > 0) {  // else dt is reported already
        c.expect(dt->value <= duration->value, *dt,
                 fmt::format("dt {} is larger than duration {}", dt->value, duration->value));
        const double steps = duration->value / dt->value;
        c.expect(steps <= kMaxSteps, *dt,
                 fmt::format("duration / dt = {:.3g} steps exceeds the limit of {:.0e}", steps, kMaxSteps));
    }
    if (!c.ok()) c.fail();

    Scenario s;
    s.unlisted_engines.tangential_unset = true;  // a file that says nothing of an engine
    s.name = name->get();
    if (description) s.description = description->get();
    s.dim = dim;
    s.room = to_vec3(*size);
    s.radius = radius->value;
    s.position = to_vec3(*position);
    s.velocity = to_vec3(*velocity);
    s.gravity = to_vec3(*gravity);
    s.alpha = alpha->value;
    s.beta = beta->value;
    s.dt = dt->value;
    s.duration = duration->value;
    s.engines = std::move(engines);
    s.externals = std::move(externals);
    s.passthrough_tables = std::move(passthrough);
    s.thresholds = std::move(thresholds);
    return s;
}

// Why oversized input is refused, `what` being "input is" or "file is N bytes,";
// reported at 1:1, where the input starts.
std::string too_large(std::string_view what) {
    return fmt::format("{} larger than the limit of {} bytes (1 MiB); a scenario file is far smaller", what,
                       kMaxInputBytes);
}

Scenario parse_unguarded(std::string_view text, const std::string& file_name,
                         const std::vector<std::string>& external_names) {
    Checker c{file_name};
    if (text.size() > kMaxInputBytes) {
        c.report({1, 1}, "", too_large("input is"));
        c.fail();
    }
    if (auto hazard = find_parser_hazard(text)) {
        c.report(hazard->where, "", std::move(hazard->reason));
        c.fail();
    }
    if (!std::all_of(text.begin(), text.end(), is_ascii))
        parse_toml(ascii_stand_in(text), c, file_name);
    const toml::table root = parse_toml(text, c, file_name);
    Scenario s = validate(root, c, std::filesystem::path(file_name).parent_path(), external_names);
    s.source = file_name;
    return s;
}

Scenario load_unguarded(const std::filesystem::path& file, const std::vector<std::string>& external_names) {
    const std::string name = file.string();
    const auto fail = [&](const std::string& reason) { throw ScenarioError({{name, 0, 0, "", reason}}); };

    // Only regular files: a FIFO or /dev/zero would block or never end.
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(file, ec);
    if (status.type() == std::filesystem::file_type::not_found) fail("cannot open: no such file");
    if (ec) fail(fmt::format("cannot open: {}", ec.message()));
    if (std::filesystem::is_directory(status)) fail("cannot open: is a directory, not a scenario file");
    if (!std::filesystem::is_regular_file(status)) fail("cannot open: not a regular file");

    // Refused by its size before a byte is read, so a 1 GB file costs nothing.
    const std::uintmax_t bytes = std::filesystem::file_size(file, ec);
    if (!ec && bytes > kMaxInputBytes)
        throw ScenarioError({{name, 1, 1, "", too_large(fmt::format("file is {} bytes,", bytes))}});

    std::ifstream in(file, std::ios::binary);
    if (!in) fail(fmt::format("cannot open: {}", std::generic_category().message(errno)));
    // One byte past the limit is enough for parse_unguarded to reject a file that grew since.
    std::string text(kMaxInputBytes + 1, '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    if (in.bad()) fail("cannot read file");
    text.resize(static_cast<std::size_t>(in.gcount()));
    return parse_unguarded(text, name, external_names);
}

// Runs `load` so that callers only ever see ScenarioError, even for bad_alloc.
template <typename Load>
Scenario guarded(const std::string& file_name, Load load) {
    try {
        return load();
    } catch (const ScenarioError&) {
        throw;
    } catch (const std::exception& e) {
        throw ScenarioError({{file_name, 0, 0, "", fmt::format("cannot load scenario: {}", e.what())}});
    }
}

}  // namespace

Scenario parse_scenario(std::string_view toml_text, const std::string& file_name,
                        const std::vector<std::string>& external_names) {
    return guarded(file_name, [&] { return parse_unguarded(toml_text, file_name, external_names); });
}

Scenario load_scenario(const std::filesystem::path& file, const std::vector<std::string>& external_names) {
    return guarded(file.string(), [&] { return load_unguarded(file, external_names); });
}

namespace {

// Each Node-hosted engine's own keys: the same list as its file's ownKeys
// (engines/node/<name>.mjs; tests/test_node_engines.cpp holds them equal).
struct HostedEngine {
    std::string_view name;
    std::span<const std::string_view> keys;
};
constexpr std::string_view kRapierKeys[] = {"wall_restitution", "restitution_combine", "wall_friction",
    "friction_combine", "sleeping", "linear_damping", "angular_damping", "timestep", "solver_iterations",
    "pgs_iterations", "prediction_distance", "allowed_linear_error", "length_unit", "soft_ccd_prediction",
    "max_ccd_substeps"};
constexpr std::string_view kJoltKeys[] = {"min_velocity_for_restitution", "linear_damping", "angular_damping",
    "allow_sleeping", "penetration_slop", "speculative_contact_distance", "baumgarte", "velocity_steps",
    "position_steps", "max_linear_velocity", "max_angular_velocity", "wall_friction", "wall_restitution",
    "linear_cast_threshold", "linear_cast_max_penetration", "body_pair_cache", "ball_mass"};
constexpr std::string_view kPhysxKeys[] = {"bounce_threshold", "solver", "restitution_combine", "friction_combine",
    "contact_offset", "rest_offset", "ccd_max_separation", "sleep_threshold", "linear_damping", "angular_damping",
    "max_angular_velocity", "iterations", "inner_steps"};
constexpr std::string_view kHavokKeys[] = {"ideal_step_time", "linear_damping", "angular_damping", "always_active",
    "max_linear_velocity", "max_angular_velocity", "wall_friction", "wall_restitution", "friction_combine",
    "restitution_combine"};
constexpr std::string_view kBox2d3Keys[] = {"restitution_threshold", "wall_restitution", "wall_friction", "sleeping",
    "substep_count", "contact_hertz", "contact_damping_ratio", "contact_push_speed", "linear_damping",
    "angular_damping"};
constexpr std::string_view kMujoco3Keys[] = {"solref", "solimp", "damper_anchor", "impedance_correction", "condim",
    "wall_friction", "cone", "integrator", "timestep", "gravity", "impratio", "noslip_iterations", "margin",
    "ball_mass", "beta_hook", "fail_on_warning", "inner_steps"};
constexpr std::string_view kPlanckKeys[] = {"velocity_threshold", "wall_offset", "linear_slop", "wall_restitution",
    "wall_friction", "sleeping", "velocity_iterations", "position_iterations", "max_translation", "linear_damping",
    "angular_damping"};
constexpr std::string_view kP2Keys[] = {"stiffness", "relaxation", "contact_skin_size", "friction_stiffness",
    "friction_relaxation", "friction_iterations", "solver_iterations", "solver_tolerance", "damping",
    "angular_damping", "sleeping", "island_split"};
constexpr std::string_view kOimoKeys[] = {"units_per_metre", "iterations", "broadphase", "randomizer", "allow_sleep",
    "wall_friction", "wall_restitution"};
constexpr std::string_view kCannonKeys[] = {"restitution", "contact_stiffness", "contact_relaxation",
    "friction_stiffness", "friction_relaxation", "iterations", "tolerance", "linear_damping", "angular_damping",
    "allow_sleep", "quat_normalize_fast", "walls", "inertia", "friction_gravity", "density"};
constexpr std::string_view kAmmoKeys[] = {"wall_restitution", "wall_friction", "rolling_friction", "walls",
    "contact_processing_threshold", "contact_breaking_threshold", "split_impulse",
    "split_impulse_penetration_threshold", "erp", "erp2", "iterations", "warm_starting", "linear_damping",
    "angular_damping", "allow_sleep", "stepping", "ccd_motion_threshold", "solver_info"};
constexpr std::string_view kMatterKeys[] = {"units_per_metre", "circle_sides", "circle_fit", "resting_thresh",
    "resting_thresh_tangent", "position_dampen", "position_warming", "slop", "friction_air", "friction_static",
    "position_iterations", "velocity_iterations", "sleeping"};
constexpr std::string_view kBox2dWasmKeys[] = {"length_scale", "restitution_threshold", "wall_restitution",
    "wall_friction", "combine_override", "skin_compensation", "sleeping", "velocity_iterations", "position_iterations",
    "warm_starting", "linear_damping", "angular_damping"};
constexpr HostedEngine kHostedEngines[] = {
    {"rapier", kRapierKeys}, {"jolt", kJoltKeys},     {"physx", kPhysxKeys},
    {"havok", kHavokKeys},   {"box2d3", kBox2d3Keys}, {"mujoco3", kMujoco3Keys},
    {"planck", kPlanckKeys}, {"p2", kP2Keys},         {"oimo", kOimoKeys},
    {"cannon", kCannonKeys}, {"ammo", kAmmoKeys},     {"matter", kMatterKeys},
    {"box2d-wasm", kBox2dWasmKeys},
};

}  // namespace

std::span<const std::string_view> hosted_engine_keys(std::string_view engine) {
    for (const HostedEngine& hosted : kHostedEngines)
        if (hosted.name == engine) return hosted.keys;
    return {};
}

bool is_hosted_engine(std::string_view engine) {
    return std::any_of(std::begin(kHostedEngines), std::end(kHostedEngines),
                       [&](const HostedEngine& hosted) { return hosted.name == engine; });
}

std::span<const std::string_view> built_in_engines() {
    return std::span<const std::string_view>(kBuiltInSimulators).subspan(2);
}

std::optional<std::string> name_problem(std::string_view name) {
    if (name.empty()) return "must not be empty";
    if (name.size() > kMaxNameBytes)
        return fmt::format("is {} characters long; the limit is {}", name.size(), kMaxNameBytes);
    if (!std::all_of(name.begin(), name.end(), is_name_char))
        return fmt::format("\"{}\" is not usable as a folder name: only letters, digits, '-', '_' and '.' are allowed",
                           printable(name));
    if (name.front() == '.') return fmt::format("\"{}\" must not start with '.'", printable(name));
    return std::nullopt;
}

}  // namespace bouncecheck
