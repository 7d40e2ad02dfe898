#include "platform/program.h"

#include "platform/printable_text.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

bool is_executable_file(const fs::path& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
}

// Holds SIGPIPE off in this thread while alive, so that writing to a program
// that has closed its input is an EPIPE error rather than the death of this
// process; a SIGPIPE raised meanwhile is consumed, not delivered.
class SigpipeHeld {
public:
    SigpipeHeld() {
        sigemptyset(&pipe_);
        sigaddset(&pipe_, SIGPIPE);
        ::pthread_sigmask(SIG_BLOCK, &pipe_, &old_);
    }
    ~SigpipeHeld() {
        const timespec zero{0, 0};
        while (::sigtimedwait(&pipe_, nullptr, &zero) > 0) {
        }
        ::pthread_sigmask(SIG_SETMASK, &old_, nullptr);
    }

private:
    sigset_t pipe_{}, old_{};
};

struct Pipe {
    int read = -1, write = -1;
};

void close_fd(int& fd) {
    if (fd >= 0) ::close(fd);
    fd = -1;
}

using Clock = std::chrono::steady_clock;

// The process groups of the programs running now, in slots a signal handler
// can read (kill_running_programs). 0: a free slot.
constexpr int kGroupSlots = 256;
std::atomic<pid_t> g_groups[kGroupSlots];

int claim_group_slot(pid_t group) {
    for (int i = 0; i < kGroupSlots; ++i) {
        pid_t expected = 0;
        if (g_groups[i].compare_exchange_strong(expected, group)) return i;
    }
    return -1;  // more programs at once than slots: that one is only killed by its run's end
}

int millis_until(Clock::time_point deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    return static_cast<int>(std::clamp<long long>(left, 0, 1000));  // wake at least once a second
}

Clock::time_point deadline_after(double seconds) {
    return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

// Keeps the last kKeptBytes of a stream.
void keep_tail(std::string& tail, std::string_view more) {
    constexpr std::size_t kKeptBytes = 8192;
    tail.append(more);
    if (tail.size() > 2 * kKeptBytes) tail.erase(0, tail.size() - kKeptBytes);
}

}  // namespace

std::optional<std::string> resolve_program(const std::string& program, const fs::path& base, std::string* why) {
    if (program.empty()) {
        if (why) *why = "the command is empty";
        return std::nullopt;
    }
    if (program.find('/') != std::string::npos) {
        const fs::path p = fs::path(program).is_absolute() ? fs::path(program) : base / program;
        if (is_executable_file(p)) return fs::absolute(p).lexically_normal().string();
        if (why) *why = fmt::format("'{}' is not an executable file", p.string());
        return std::nullopt;
    }
    const char* path = std::getenv("PATH");
    std::stringstream dirs(path ? path : "/usr/local/bin:/usr/bin:/bin");
    for (std::string dir; std::getline(dirs, dir, ':');) {
        if (is_executable_file(fs::path(dir.empty() ? "." : dir) / program)) return program;
    }
    if (why) *why = fmt::format("'{}' is not found on PATH", program);
    return std::nullopt;
}

std::string last_lines(std::string_view text, std::size_t count) {
    std::vector<std::string_view> lines;
    while (!text.empty()) {
        const std::size_t end = std::min(text.find('\n'), text.size());
        std::string_view line = text.substr(0, end);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        if (!line.empty()) lines.push_back(line);
        text.remove_prefix(std::min(end + 1, text.size()));
    }
    const std::size_t from = lines.size() > count ? lines.size() - count : 0;
    std::string out;
    for (std::size_t i = from; i < lines.size(); ++i) {
        if (i > from) out += " | ";
        out += printable_text(lines[i]);  // a child may write anything: escapes, bytes that are not UTF-8
    }
    return out;
}

std::string ProgramEnd::describe(double silence_timeout_seconds) const {
    std::string what;
    switch (how) {
        case How::exited:
            if (code == 0) return {};
            what = fmt::format("exit status {}", code);
            break;
        case How::signalled: what = fmt::format("killed by signal {} ({})", code, ::strsignal(code)); break;
        case How::timed_out:
            what = fmt::format("no output for {} s (--external-timeout): killed", silence_timeout_seconds);
            break;
        case How::stopped: what = "stopped by the harness"; break;
        case How::not_started: return fmt::format("cannot start: {}", error);
    }
    return stderr_tail.empty() ? what : fmt::format("{}; stderr: {}", what, stderr_tail);
}

ProgramEnd run_program(const ProgramRequest& request) {
    ProgramEnd end;
    if (request.argv.empty()) {
        end.error = "the command is empty";
        return end;
    }
    // Close-on-exec from birth: a program started by another thread at the
    // same time must not inherit these ends (it would hold our pipes open).
    Pipe in, out, err;
    for (Pipe* p : {&in, &out, &err}) {
        int fds[2];
        if (::pipe2(fds, O_CLOEXEC) != 0) {
            end.error = fmt::format("pipe: {}", std::strerror(errno));
            for (Pipe* q : {&in, &out, &err}) close_fd(q->read), close_fd(q->write);
            return end;
        }
        *p = Pipe{fds[0], fds[1]};
    }

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, in.read, STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, out.write, STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, err.write, STDERR_FILENO);
    if (!request.cwd.empty()) posix_spawn_file_actions_addchdir_np(&actions, request.cwd.c_str());
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    // A group of its own, so that the program's own children are killed with
    // it; default signal handling and an empty mask, whatever this thread has.
    sigset_t none, defaults;
    sigemptyset(&none);
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGPIPE);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    posix_spawnattr_setpgroup(&attr, 0);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setsigdefault(&attr, &defaults);

    std::vector<char*> argv;
    for (const std::string& a : request.argv) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_t pid = -1;
    const int spawned = ::posix_spawnp(&pid, argv[0], &actions, &attr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    close_fd(in.read);
    close_fd(out.write);
    close_fd(err.write);
    if (spawned != 0) {
        end.error = fmt::format("{}: {}", request.argv[0], std::strerror(spawned));
        for (int* fd : {&in.write, &out.read, &err.read}) close_fd(*fd);
        return end;
    }
    const int group_slot = claim_group_slot(pid);
    for (int fd : {in.write, out.read, err.read}) ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);

    const SigpipeHeld held;
    std::string err_tail;
    char buffer[65536];
    std::size_t written = 0;
    if (request.input.empty()) close_fd(in.write);
    auto deadline = deadline_after(request.silence_timeout_seconds);
    const auto drain_stderr = [&] {
        for (;;) {
            const ssize_t n = ::read(err.read, buffer, sizeof buffer);
            if (n > 0) keep_tail(err_tail, {buffer, static_cast<std::size_t>(n)});
            else if (n < 0 && errno == EINTR) continue;
            else {
                if (n == 0) close_fd(err.read);
                return;
            }
        }
    };

    // Until standard output ends: feed the input, pass the output on, keep
    // the tail of standard error (a program blocked on a full stderr pipe
    // would otherwise never finish).
    std::optional<ProgramEnd::How> cut;  // why the harness ended the run
    while (out.read >= 0) {
        pollfd fds[3] = {{in.write, POLLOUT, 0}, {out.read, POLLIN, 0}, {err.read, POLLIN, 0}};
        const int ready = ::poll(fds, 3, millis_until(deadline));
        if (ready < 0 && errno != EINTR) {
            end.error = fmt::format("poll: {}", std::strerror(errno));
            cut = ProgramEnd::How::stopped;
            break;
        }
        if (Clock::now() >= deadline) {
            cut = ProgramEnd::How::timed_out;
            break;
        }
        if (ready <= 0) continue;
        if (fds[0].revents & (POLLOUT | POLLERR | POLLHUP)) {
            const ssize_t n = ::write(in.write, request.input.data() + written, request.input.size() - written);
            if (n > 0) written += static_cast<std::size_t>(n);
            // EPIPE: the program closed its input unread; what it does next decides.
            if ((n < 0 && errno != EAGAIN && errno != EINTR) || written == request.input.size()) close_fd(in.write);
        }
        if (fds[2].revents & (POLLIN | POLLHUP | POLLERR)) drain_stderr();
        if (fds[1].revents & (POLLIN | POLLHUP | POLLERR)) {
            const ssize_t n = ::read(out.read, buffer, sizeof buffer);
            if (n > 0) {
                deadline = deadline_after(request.silence_timeout_seconds);
                if (!request.on_output({buffer, static_cast<std::size_t>(n)})) {
                    cut = ProgramEnd::How::stopped;
                    break;
                }
            } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
                close_fd(out.read);
            }
        }
    }
    close_fd(in.write);

    // Standard output has ended: wait for the program itself to exit (within
    // the same silence limit), without reaping it yet, so that its process
    // group cannot be reused before it is killed below.
    while (!cut) {
        siginfo_t info{};
        if (::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == pid)
            break;
        if (Clock::now() >= deadline) {
            cut = ProgramEnd::How::timed_out;
            break;
        }
        pollfd fd{err.read, POLLIN, 0};
        if (err.read >= 0 && ::poll(&fd, 1, 20) > 0) drain_stderr();
        else if (err.read < 0) ::usleep(20000);
    }
    ::kill(-pid, SIGKILL);  // the group: the program if the harness cut it short, and any child it left
    if (group_slot >= 0) g_groups[group_slot].store(0);  // before reaping: the group id stays ours until then
    if (err.read >= 0) drain_stderr();
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    close_fd(out.read);
    close_fd(err.read);

    end.stderr_tail = last_lines(err_tail, 5);
    if (cut) {
        end.how = *cut;
    } else if (WIFSIGNALED(status)) {
        end.how = ProgramEnd::How::signalled;
        end.code = WTERMSIG(status);
    } else {
        end.how = ProgramEnd::How::exited;
        end.code = WEXITSTATUS(status);
    }
    return end;
}

void kill_running_programs() {
    for (std::atomic<pid_t>& group : g_groups)
        if (const pid_t g = group.load(); g > 0) ::kill(-g, SIGKILL);  // async-signal-safe
}

}  // namespace bouncecheck
