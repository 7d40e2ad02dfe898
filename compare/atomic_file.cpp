#include "compare/atomic_file.h"

#include <fmt/format.h>

#include <stdexcept>
#include <unistd.h>

namespace bouncecheck {

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
    // A name unique to this process: two runs writing the same folder never share a temp file.
    temp_ = target_;
    temp_ += fmt::format(".tmp.{}", ::getpid());
    file_ = std::fopen(temp_.c_str(), "wb");
    if (!file_) throw std::runtime_error(fmt::format("cannot write {}", temp_.string()));
}

AtomicFile::~AtomicFile() {
    if (file_) {
        std::fclose(file_);
        std::error_code ignored;
        std::filesystem::remove(temp_, ignored);
    }
}

void AtomicFile::write(std::string_view bytes) {
    if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
        throw std::runtime_error(fmt::format("write failed: {}", temp_.string()));
}

void AtomicFile::commit() {
    const bool flushed = std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
    const bool closed = std::fclose(file_) == 0;
    file_ = nullptr;
    if (!flushed || !closed) {
        std::error_code ignored;
        std::filesystem::remove(temp_, ignored);
        throw std::runtime_error(fmt::format("write failed: {}", temp_.string()));
    }
    std::filesystem::rename(temp_, target_);
}

void write_file_atomically(const std::filesystem::path& target, std::string_view contents) {
    AtomicFile file(target);
    file.write(contents);
    file.commit();
}

}  // namespace bouncecheck
