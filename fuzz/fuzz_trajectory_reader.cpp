// libFuzzer target for the trajectory reader (external/trajectory_reader.h),
// which reads an external program's standard output as it streams in and an
// imported --trajectory file. The bytes are read three times: whole, in
// pieces whose sizes come from the bytes themselves, and one byte at a time,
// since a pipe may cut the stream anywhere. Every reading must reach the same
// verdict (the same problem, or none) after the same rows; a row handed on
// must be finite; an accepted trajectory must have the clock's row count; a
// problem must name its line and print as it is. Anything else is a finding.
#include "external/trajectory_reader.h"

#include "platform/printable_text.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_trajectory_reader: %s\n%s\n", what, detail.c_str());
    std::abort();
}

// seed-2d and seed-3d cut to 6 s: 201 rows, so that the seeds (their first
// rows, as `run --trajectories` writes them) are whole trajectories.
bouncecheck::Scenario fuzz_scenario(int dim) {
    bouncecheck::Scenario s;
    s.name = dim == 2 ? "fuzz-2d" : "fuzz-3d";
    s.dim = dim;
    if (dim == 2) {
        s.room = {1, 1, 0};
        s.position = {0.5, 0.95, 0};
        s.velocity = {0.3, 0, 0};
        s.gravity = {0, -0.0981, 0};
    }
    s.duration = 6.0;
    return s;
}

// What a reading ends with. `digest` folds every row's bits, so two readings
// that agree on it handed on the same rows.
struct Verdict {
    std::optional<bouncecheck::RowProblem> problem;
    std::int64_t rows = 0;
    std::int64_t rows_handed_on = 0;
    std::uint64_t digest = 14695981039346656037u;
};

class CountingSink {
public:
    CountingSink(int dim, Verdict& verdict) : dim_(dim), verdict_(verdict) {}
    bool operator()(const bouncecheck::State& s) {
        const double values[] = {s.t, s.p[0], s.p[1], s.p[2], s.v[0], s.v[1], s.v[2]};
        for (const double v : values) {
            if (!std::isfinite(v)) finding("a row handed on with a non-finite value", std::to_string(v));
            std::uint64_t bits;
            std::memcpy(&bits, &v, sizeof bits);
            verdict_.digest = (verdict_.digest ^ bits) * 1099511628211u;
        }
        // State's promise: in 2D the third components are zero.
        if (dim_ == 2 && (s.p[2] != 0 || s.v[2] != 0)) finding("a 2D row with a third component", "");
        ++verdict_.rows_handed_on;
        return true;
    }

private:
    int dim_;
    Verdict& verdict_;
};

// `next_piece()` bytes at a time, then the end of the stream, as
// read_trajectory_file and the external simulator drive the reader.
template <class NextPiece>
Verdict read(const bouncecheck::Scenario& s, std::string_view bytes, NextPiece&& next_piece) {
    Verdict verdict;
    bouncecheck::TrajectoryReader reader(s);
    CountingSink sink(s.dim, verdict);
    bool more = true;
    for (std::size_t at = 0; more && at < bytes.size();) {
        const std::size_t n = next_piece();
        more = reader.feed(bytes.substr(at, n), sink);
        at += n;
    }
    if (more) reader.finish(sink);
    verdict.problem = reader.problem();
    verdict.rows = reader.rows();
    if (verdict.rows_handed_on != verdict.rows) finding("rows counted and rows handed on differ", "");
    return verdict;
}

std::string describe(const Verdict& v) {
    return (v.problem ? v.problem->format() : std::string("accepted")) + " after " + std::to_string(v.rows) +
           " rows";
}

void check_same(const Verdict& whole, const Verdict& pieces, const char* how) {
    const bool same_problem = whole.problem.has_value() == pieces.problem.has_value() &&
                              (!whole.problem || (whole.problem->line == pieces.problem->line &&
                                                  whole.problem->field == pieces.problem->field &&
                                                  whole.problem->reason == pieces.problem->reason));
    if (!same_problem || whole.rows != pieces.rows || whole.digest != pieces.digest)
        finding(how, "whole: " + describe(whole) + "\npieces: " + describe(pieces));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    // The 3D scenario when the bytes start as its header does, so that both
    // headers' rows get read; the 2D one otherwise.
    const bouncecheck::Scenario s = fuzz_scenario(bytes.substr(0, 8) == "t,x,y,z," ? 3 : 2);

    const Verdict whole = read(s, bytes, [&] { return bytes.size(); });

    // Piece sizes from a hash of the bytes: any change to the input moves
    // every cut. Mostly short pieces (a cut inside a number, a "\r\n" split),
    // now and then one longer than a line may be (4096 bytes).
    std::uint64_t state = 14695981039346656037u;
    for (const char c : bytes) state = (state ^ static_cast<unsigned char>(c)) * 1099511628211u;
    const auto hashed_piece = [&]() -> std::size_t {
        state ^= state << 13, state ^= state >> 7, state ^= state << 17;
        return (state & 7) == 0 ? 1 + state % 6000 : 1 + (state >> 8) % 64;
    };
    check_same(whole, read(s, bytes, hashed_piece), "a different verdict in pieces");
    check_same(whole, read(s, bytes, [] { return std::size_t{1}; }),
               "a different verdict one byte at a time");

    if (!whole.problem && whole.rows != bouncecheck::TrajectoryReader(s).expected_rows())
        finding("accepted a trajectory without the clock's row count", describe(whole));
    if (whole.problem) {
        const std::string text = whole.problem->format();
        if (whole.problem->line < 1 || whole.problem->reason.empty()) finding("a problem without line or reason", text);
        // The reason is shown on the terminal and in the reports: quoted bytes go through printable_text.
        if (bouncecheck::printable_text(text) != text) finding("a problem that does not print as it is", text);
    }
    return 0;
}
