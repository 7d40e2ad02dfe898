#include "platform/atomic_file.h"

#include "platform/program.h"

#include <fmt/format.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <stdexcept>
#include <unistd.h>

namespace bouncecheck {

namespace {

// The temporary files being written, in a form a signal handler can read:
// fixed slots of plain characters. A slot is claimed (filling), then
// published (live) once its path is whole; the handler touches live ones only.
constexpr int kSlots = 64;
constexpr std::size_t kPathMax = 4096;
enum SlotState : int { kFree, kFilling, kLive };
struct Slot {
    std::atomic<int> state{kFree};
    char path[kPathMax];
};
Slot g_slots[kSlots];

int claim_slot(const std::filesystem::path& temp) {
    const std::string& p = temp.native();
    if (p.size() >= kPathMax) return -1;
    for (int i = 0; i < kSlots; ++i) {
        int expected = kFree;
        if (!g_slots[i].state.compare_exchange_strong(expected, kFilling)) continue;
        std::memcpy(g_slots[i].path, p.c_str(), p.size() + 1);
        g_slots[i].state.store(kLive);
        return i;
    }
    return -1;  // more than kSlots files at once: that one is only cleaned up by the destructor
}

void release_slot(int slot) {
    if (slot >= 0) g_slots[slot].state.store(kFree);
}

extern "C" void remove_unfinished_and_die(int sig) {
    kill_running_programs();
    for (Slot& slot : g_slots)
        if (slot.state.load() == kLive) ::unlink(slot.path);  // async-signal-safe
    std::signal(sig, SIG_DFL);
    std::raise(sig);
}

}  // namespace

void remove_unfinished_files_on_interrupt() {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, remove_unfinished_and_die);
}

RemovedOnInterrupt::RemovedOnInterrupt(const std::filesystem::path& path) : slot_(claim_slot(path)) {}

RemovedOnInterrupt::~RemovedOnInterrupt() { release_slot(slot_); }

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
    // A name unique to this process: two runs writing the same folder never share a temp file.
    temp_ = target_;
    temp_ += fmt::format(".tmp.{}", ::getpid());
    slot_ = claim_slot(temp_);
    file_ = std::fopen(temp_.c_str(), "wb");
    if (!file_) {
        release_slot(slot_);
        throw std::runtime_error(fmt::format("cannot write {}", temp_.string()));
    }
}

AtomicFile::~AtomicFile() {
    if (file_) {
        std::fclose(file_);
        std::error_code ignored;
        std::filesystem::remove(temp_, ignored);
    }
    release_slot(slot_);
}

void AtomicFile::write(std::string_view bytes) {
    if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
        throw std::runtime_error(fmt::format("write failed: {}", temp_.string()));
}

void AtomicFile::commit() {
    const bool flushed = std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
    const bool closed = std::fclose(file_) == 0;
    const int write_error = errno;
    file_ = nullptr;
    std::error_code renamed;
    if (flushed && closed) std::filesystem::rename(temp_, target_, renamed);
    if (!flushed || !closed || renamed) {
        // Nothing half-written stays: the target keeps what it had.
        std::error_code ignored;
        std::filesystem::remove(temp_, ignored);
        release_slot(slot_);
        slot_ = -1;
        throw std::runtime_error(fmt::format("cannot write {}: {}", target_.string(),
                                             renamed ? renamed.message() : std::string(std::strerror(write_error))));
    }
    release_slot(slot_);
    slot_ = -1;
}

void OutputWrites::finish() const {
    if (failures_.empty()) return;
    std::string all;
    for (const std::string& failure : failures_) all += (all.empty() ? "" : "; ") + failure;
    throw std::runtime_error(failures_.size() == 1 ? all : fmt::format("{} outputs not written: {}", failures_.size(), all));
}

void write_file_atomically(const std::filesystem::path& target, std::string_view contents) {
    write_file_atomically(target, {contents});
}

void write_file_atomically(const std::filesystem::path& target, std::initializer_list<std::string_view> pieces) {
    AtomicFile file(target);
    for (std::string_view piece : pieces) file.write(piece);
    file.commit();
}

}  // namespace bouncecheck
