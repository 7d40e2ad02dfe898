#include "external/trajectory_reader.h"

#include "platform/printable_text.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>

namespace bouncecheck {

namespace {

constexpr std::string_view kHeader2d = "t,x,y,vx,vy";
constexpr std::string_view kHeader3d = "t,x,y,z,vx,vy,vz";
constexpr std::array<const char*, 5> kColumns2d{"t", "x", "y", "vx", "vy"};
constexpr std::array<const char*, 7> kColumns3d{"t", "x", "y", "z", "vx", "vy", "vz"};

// Untrusted text quoted in a reason: short, one line.
std::string quoted(std::string_view text) {
    return fmt::format("'{}{}'", printable_text(text.substr(0, 40)), text.size() > 40 ? "..." : "");
}

}  // namespace

std::string RowProblem::format() const {
    return fmt::format("line {}: {}{}", line, field.empty() ? "" : field + ": ", reason);
}

TrajectoryReader::TrajectoryReader(const Scenario& s)
    : dim_(s.dim), dt_(s.dt), header_(s.dim == 2 ? kHeader2d : kHeader3d),
      expected_rows_(document_step_count(s.dt, s.duration) + 1), clock_(s.dt, s.duration) {
    partial_.reserve(256);
}

bool TrajectoryReader::fail_long_line() {
    problem_ = RowProblem{line_ + 1, "", fmt::format("a line longer than {} bytes", kMaxLineBytes)};
    return false;
}

std::string TrajectoryReader::fmt_too_few() const {
    return fmt::format("the trajectory ends after {} rows; the scenario's clock takes {} (steps + 1)", rows_,
                       expected_rows_);
}

bool TrajectoryReader::take_line(std::string_view text) {
    ++line_;
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    if (line_ == 1) {
        if (text != header_)
            problem_ = RowProblem{line_, "", fmt::format("expected the header '{}' ({}D scenario), got {}", header_,
                                                         dim_, quoted(text))};
        return false;
    }
    if (ended_) {
        problem_ = RowProblem{line_, "", "nothing may follow the #end line"};
        return false;
    }
    if (text.starts_with("#f64")) {
        take_block_line(text);
        return false;
    }
    if (text.starts_with("#end")) {
        if (rows_ < expected_rows_) {
            problem_ = RowProblem{line_, "", fmt::format("an #end line after {} rows; the scenario's clock takes {} "
                                                         "(steps + 1)",
                                                         rows_, expected_rows_)};
            return false;
        }
        take_end_line(text);
        return false;
    }
    if (rows_ == expected_rows_) {
        problem_ = RowProblem{line_, "",
                              fmt::format("more rows than the {} the scenario's clock takes (steps + 1)", expected_rows_)};
        return false;
    }
    const int fields = 1 + 2 * dim_;
    const char* const* names = dim_ == 2 ? kColumns2d.data() : kColumns3d.data();
    double values[7];
    const char* at = text.data();
    const char* const end = text.data() + text.size();
    for (int f = 0; f < fields; ++f) {
        const char* stop = static_cast<const char*>(std::memchr(at, ',', static_cast<std::size_t>(end - at)));
        if (!stop) stop = end;
        if (f < fields - 1 && stop == end) {
            problem_ = RowProblem{line_, names[f + 1],
                                  fmt::format("missing: the row has {} fields, expected {} ({})", f + 1, fields, header_)};
            return false;
        }
        const char* from = at;
        if (from < stop && *from == '+') ++from;  // strtod reads a leading '+'; from_chars does not
        const auto [parsed, error] = std::from_chars(from, stop, values[f]);
        if (from == stop || error != std::errc() || parsed != stop) {
            const std::string_view field(at, static_cast<std::size_t>(stop - at));
            problem_ = RowProblem{line_, names[f],
                                  error == std::errc::result_out_of_range
                                      ? fmt::format("{} is out of the range of a double", quoted(field))
                                      : fmt::format("not a number: {}", quoted(field))};
            return false;
        }
        at = stop + 1;
    }
    if (at <= end) {
        problem_ = RowProblem{line_, "", fmt::format("more than {} fields ({})", fields, header_)};
        return false;
    }
    return take_values(values, /*binary=*/false);
}

bool TrajectoryReader::take_values(const double* values, bool binary) {
    const char* const* names = dim_ == 2 ? kColumns2d.data() : kColumns3d.data();
    const char* const row = binary ? " (a binary row)" : "";
    for (int f = 0; f < 1 + 2 * dim_; ++f)
        if (!std::isfinite(values[f])) {
            problem_ = RowProblem{line_, names[f], fmt::format("not finite: {}{}", values[f], row)};
            return false;
        }
    // Sample k must be the clock's k-th: a missing or extra row would shift
    // every comparison after it.
    if (rows_ > 0) clock_.advance();
    if (!(std::abs(values[0] - clock_.t()) <= 0.5 * dt_)) {
        problem_ = RowProblem{line_, "t",
                              fmt::format("{} is not row {}'s time on the scenario's clock ({}, dt = {}){}", values[0],
                                          rows_, clock_.t(), dt_, row)};
        return false;
    }
    state_.t = values[0];
    for (int i = 0; i < dim_; ++i) {
        state_.p[i] = values[1 + i];
        state_.v[i] = values[1 + dim_ + i];
    }
    ++rows_;
    return true;
}

bool TrajectoryReader::take_binary_row(std::string_view bytes) {
    ++line_;
    --binary_rows_left_;
    double values[7];
    for (int f = 0; f < 1 + 2 * dim_; ++f) {
        // Little-endian whatever this machine's order (docs/external.md).
        std::uint64_t bits = 0;
        for (int b = 7; b >= 0; --b) bits = bits << 8 | static_cast<unsigned char>(bytes[static_cast<std::size_t>(8 * f + b)]);
        values[f] = std::bit_cast<double>(bits);
    }
    return take_values(values, /*binary=*/true);
}

void TrajectoryReader::take_block_line(std::string_view text) {
    const std::string_view count = text.substr(4);  // " N"
    std::int64_t n = 0;
    bool well_formed = count.size() >= 2 && count.front() == ' ';
    if (well_formed) {
        const auto [parsed, error] = std::from_chars(count.data() + 1, count.data() + count.size(), n);
        well_formed = error == std::errc() && parsed == count.data() + count.size() && n >= 1 && n <= kMaxBlockRows;
    }
    if (!well_formed) {
        problem_ = RowProblem{line_, "", fmt::format("expected '#f64 N' with N from 1 to {} (a block of N binary rows), got {}",
                                                     kMaxBlockRows, quoted(text))};
        return;
    }
    if (n > expected_rows_ - rows_) {
        problem_ = RowProblem{line_, "", fmt::format("a block of {} binary rows after {}; the scenario's clock takes {} "
                                                     "(steps + 1)",
                                                     n, rows_, expected_rows_)};
        return;
    }
    binary_rows_left_ = n;
}

std::string TrajectoryReader::fmt_cut_block() const {
    return fmt::format("the stream ends inside a block of binary rows, {} of them still to come: cut off?",
                       binary_rows_left_);
}

void TrajectoryReader::take_end_line(std::string_view text) {
    ended_ = true;
    const std::string_view rest = text.substr(4);
    if (rest.empty()) return;  // "#end" alone: nothing reported
    const auto refuse = [&](const char* field, std::string reason) { problem_ = RowProblem{line_, field, std::move(reason)}; };
    if (rest.front() != ' ') return refuse("", fmt::format("expected '#end' or '#end {{JSON object}}', got {}", quoted(text)));
    // A short flat object (the line is at most 4096 bytes): nesting is refused as it is read.
    const nlohmann::json::parser_callback_t flat = [](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
        if (depth > 4) throw std::runtime_error("nested");
        return true;
    };
    nlohmann::json end;
    try {
        end = nlohmann::json::parse(rest.substr(1), flat, /*allow_exceptions=*/false);
    } catch (const std::runtime_error&) {
        return refuse("", "the #end line's JSON is nested deeper than 4 levels");
    }
    if (end.is_discarded() || !end.is_object())
        return refuse("", fmt::format("the #end line holds no JSON object: {}", quoted(rest.substr(1))));
    // Other keys are for later versions of the protocol: ignored.
    if (const auto it = end.find("step_seconds"); it != end.end()) {
        if (!it->is_number() || !std::isfinite(it->get<double>()) || it->get<double>() < 0)
            return refuse("step_seconds", fmt::format("must be a finite number of seconds >= 0, got {}",
                                                      bouncecheck::quoted(it->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace))));
        step_seconds_ = it->get<double>();
    }
}

std::optional<std::string> read_trajectory_file(const std::string& file, const Scenario& s,
                                                const std::function<bool(const State&)>& on_state) {
    // A recorded trajectory is read twice, checked before anything runs and
    // replayed in the run: a pipe (a process substitution) would pass the
    // check and then be empty, so only a regular file is taken.
    std::error_code ec;
    const auto status = std::filesystem::status(file, ec);
    if (!ec && status.type() != std::filesystem::file_type::regular)
        return fmt::format("{}: not a regular file: a recorded trajectory is read twice (checked, then compared), so "
                           "give a file, not a pipe",
                           file);
    const std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(file.c_str(), "rb"), &std::fclose);
    if (!in) return fmt::format("{}: cannot open: {}", file, std::strerror(errno));
    TrajectoryReader reader(s);
    char buffer[65536];
    bool more = true;
    while (more) {
        const std::size_t n = std::fread(buffer, 1, sizeof buffer, in.get());
        if (n > 0 && !reader.feed({buffer, n}, on_state)) {
            if (!reader.problem()) return std::nullopt;  // stopped by on_state
            break;
        }
        if (n < sizeof buffer) {
            if (std::ferror(in.get())) return fmt::format("{}: cannot read: {}", file, std::strerror(errno));
            more = false;
        }
    }
    if (!reader.problem() && !reader.finish(on_state) && !reader.problem()) return std::nullopt;
    if (const auto& p = reader.problem()) return fmt::format("{}:{}: {}{}", file, p->line, p->field.empty() ? "" : p->field + ": ", p->reason);
    return std::nullopt;
}

}  // namespace bouncecheck
