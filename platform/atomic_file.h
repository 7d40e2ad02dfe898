// Output files are written aside and renamed into place, so no reader (or an
// interrupted run) ever sees half a file.
#pragma once

#include <cstdio>
#include <filesystem>
#include <exception>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

class AtomicFile {
public:
    // Opens a temporary file beside `target`; throws std::runtime_error on failure.
    explicit AtomicFile(std::filesystem::path target);
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    ~AtomicFile();  // removes the temporary file unless commit() succeeded

    void write(std::string_view bytes);
    // Flushes, closes and renames the temporary file onto the target. On
    // failure the temporary file is removed and the error names the target.
    void commit();

private:
    std::filesystem::path target_;
    std::filesystem::path temp_;
    std::FILE* file_ = nullptr;
    int slot_ = -1;  // in the registry the interrupt handler cleans up
};

// A temporary file of another kind (an external program's settings file)
// that an interrupt must not leave behind either: while this lives, the
// interrupt handler below removes `path`. Removing it otherwise stays the
// owner's job.
class RemovedOnInterrupt {
public:
    explicit RemovedOnInterrupt(const std::filesystem::path& path);
    RemovedOnInterrupt(const RemovedOnInterrupt&) = delete;
    RemovedOnInterrupt& operator=(const RemovedOnInterrupt&) = delete;
    ~RemovedOnInterrupt();

private:
    int slot_ = -1;
};

// A set of outputs written so that one that cannot be (a folder in its
// place) costs only itself: each write is attempted, then finish() throws
// one std::runtime_error naming every failure.
class OutputWrites {
public:
    template <class Write>
    void attempt(Write&& write) {
        try {
            write();
        } catch (const std::exception& e) {
            failures_.emplace_back(e.what());
        }
    }
    void finish() const;

private:
    std::vector<std::string> failures_;
};

// Writes `contents` to `target` atomically.
void write_file_atomically(const std::filesystem::path& target, std::string_view contents);
// The same for contents in pieces, written one after another: a large piece
// (a page's inlined library) is written from where it is, never joined.
void write_file_atomically(const std::filesystem::path& target, std::initializer_list<std::string_view> pieces);

// On SIGINT, SIGTERM or SIGHUP: removes every temporary file still open and
// kills every external program still running (program.h), then dies of the
// same signal (so the caller's shell sees the interruption). The
// targets are untouched: each is either absent or a complete earlier file.
void remove_unfinished_files_on_interrupt();

}  // namespace bouncecheck
