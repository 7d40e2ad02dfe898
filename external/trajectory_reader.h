// Reads a trajectory in the `--trajectories` CSV format (docs/external.md,
// Output) as it streams in, from an external program's standard output or
// from a file: the header, then one row per state on the document's clock,
// each a text line or a row of a binary `#f64 N` block.
// Rows are parsed in place, without allocating per row, and handed on one by
// one: the trajectory is never held in memory.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/document_clock.h"
#include "simulators/state.h"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace bouncecheck {

// Where and why a trajectory is malformed.
struct RowProblem {
    std::int64_t line = 0;  // 1-based; the header is line 1
    std::string field;      // the column ("vx"), or empty for the whole line
    std::string reason;
    // "line L: FIELD: REASON" (the parts that are empty left out).
    std::string format() const;
};

class TrajectoryReader {
public:
    // Expects the header of s.dim and the document clock's steps + 1 rows.
    explicit TrajectoryReader(const Scenario& s);

    // A piece of the stream; `on_state(const State&)` gets each complete row
    // and returns false to stop. False once the trajectory is malformed
    // (problem()) or on_state said stop.
    template <class OnState>
    bool feed(std::string_view bytes, OnState&& on_state) {
        while (!bytes.empty()) {
            if (binary_rows_left_ > 0) {
                // A binary row: whole in this piece, or gathered across pieces.
                const std::size_t row_bytes = binary_row_bytes();
                std::string_view row;
                if (partial_.empty() && bytes.size() >= row_bytes) {
                    row = bytes.substr(0, row_bytes);
                    bytes.remove_prefix(row_bytes);
                } else {
                    const std::size_t take = std::min(row_bytes - partial_.size(), bytes.size());
                    partial_.append(bytes.substr(0, take));
                    bytes.remove_prefix(take);
                    if (partial_.size() < row_bytes) return true;
                    row = partial_;
                }
                const bool state = take_binary_row(row);
                partial_.clear();
                if (problem_) return false;
                if (state && !on_state(state_)) return false;
                continue;
            }
            const std::size_t end = bytes.find('\n');
            if (end == std::string_view::npos) {
                if (partial_.size() + bytes.size() > kMaxLineBytes) return fail_long_line();
                partial_.append(bytes);
                return true;
            }
            std::string_view text = bytes.substr(0, end);
            bytes.remove_prefix(end + 1);
            // The limit holds however the line arrived: whole in one piece, or in several.
            if (partial_.empty() && text.size() > kMaxLineBytes) return fail_long_line();
            if (!partial_.empty()) {
                if (partial_.size() + text.size() > kMaxLineBytes) return fail_long_line();
                partial_.append(text);
                text = partial_;
            }
            const bool state = take_line(text);
            partial_.clear();
            if (problem_) return false;
            if (state && !on_state(state_)) return false;
        }
        return true;
    }
    // The end of the stream: too few rows, or a last line without its
    // newline. That one is refused, not parsed: a stream cut mid-row can
    // still leave a number ("0.123" of "0.12345678"), which would pass.
    template <class OnState>
    bool finish(OnState&& on_state) {
        (void)on_state;
        if (binary_rows_left_ > 0) {
            problem_ = RowProblem{line_ + 1, "",
                                  fmt_cut_block()};
            partial_.clear();
            return false;
        }
        if (!partial_.empty()) {
            problem_ = RowProblem{line_ + 1, "", "the last line has no newline at its end: cut off?"};
            partial_.clear();
            return false;
        }
        if (rows_ < expected_rows_) {
            problem_ = RowProblem{line_ + 1, "",
                                  rows_ == 0 && line_ == 0
                                      ? "no header: the trajectory is empty"
                                      : fmt_too_few()};
            return false;
        }
        return true;
    }

    const std::optional<RowProblem>& problem() const { return problem_; }
    // What the program measured of its own engine's steps, when its stream
    // ends with `#end {"step_seconds": S}` (docs/external.md, Output).
    std::optional<double> step_seconds() const { return step_seconds_; }
    // The `#end` line has been read, well formed: a session's reply is whole.
    bool ended() const { return ended_ && !problem_; }
    std::int64_t rows() const { return rows_; }
    std::int64_t expected_rows() const { return expected_rows_; }

private:
    static constexpr std::size_t kMaxLineBytes = 4096;
    // The most rows one `#f64 N` block may announce (docs/external.md).
    static constexpr std::int64_t kMaxBlockRows = 1 << 16;
    // One line: the header, a text row parsed into state_, or a block's
    // `#f64 N` line. True for a row.
    bool take_line(std::string_view text);
    // One row of a binary block (binary_row_bytes() bytes). True for a row.
    bool take_binary_row(std::string_view bytes);
    // A row's values, from text or binary: checked and put in state_. True for a row.
    bool take_values(const double* values, bool binary);
    // `#f64 N`: the next N rows are binary.
    void take_block_line(std::string_view text);
    std::size_t binary_row_bytes() const { return 8 * static_cast<std::size_t>(1 + 2 * dim_); }
    std::string fmt_cut_block() const;
    // The optional `#end` line after the last row.
    void take_end_line(std::string_view text);
    bool fail_long_line();
    std::string fmt_too_few() const;

    int dim_;
    double dt_;
    std::string_view header_;
    std::int64_t expected_rows_;
    std::int64_t line_ = 0, rows_ = 0;
    DocumentClock clock_;
    State state_;
    std::string partial_;  // a line, or a binary row, split across pieces
    std::int64_t binary_rows_left_ = 0;  // of the current `#f64 N` block
    std::optional<RowProblem> problem_;
    bool ended_ = false;  // the #end line was read: nothing may follow
    std::optional<double> step_seconds_;
};

// Reads a whole trajectory file through a TrajectoryReader, `on_state`
// getting each row and returning false to stop: nothing if it is a
// trajectory of `s` (or was stopped), else what is wrong with it
// ("FILE:LINE: FIELD: REASON", or why it cannot be read).
std::optional<std::string> read_trajectory_file(const std::string& file, const Scenario& s,
                                                const std::function<bool(const State&)>& on_state);

}  // namespace bouncecheck
