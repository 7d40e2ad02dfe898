#include "reports/trajectory_csv.h"

#include <fmt/format.h>

#include <iterator>

namespace bouncecheck {

namespace {
constexpr std::size_t kFlushBytes = 1 << 20;
}

TrajectoryCsv::TrajectoryCsv(const std::filesystem::path& target, int dim) : file_(target), dim_(dim) {
    buffer_ = dim == 2 ? "t,x,y,vx,vy\n" : "t,x,y,z,vx,vy,vz\n";
}

void TrajectoryCsv::write(const State& s) {
    auto out = std::back_inserter(buffer_);
    fmt::format_to(out, "{:.17g}", s.t);
    for (int i = 0; i < dim_; ++i) fmt::format_to(out, ",{:.17g}", s.p[i]);
    for (int i = 0; i < dim_; ++i) fmt::format_to(out, ",{:.17g}", s.v[i]);
    buffer_.push_back('\n');
    if (buffer_.size() >= kFlushBytes) flush();
}

void TrajectoryCsv::flush() {
    file_.write(buffer_);
    buffer_.clear();
}

void TrajectoryCsv::commit() {
    flush();
    file_.commit();
}

}  // namespace bouncecheck
