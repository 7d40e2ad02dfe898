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
#include <sys/prctl.h>
#include <sys/resource.h>
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

// The first executable file named `program` in a folder of PATH, as execvp
// looks (an empty entry is the current folder).
std::optional<fs::path> find_on_path(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::stringstream dirs(path ? path : "/usr/local/bin:/usr/bin:/bin");
    for (std::string dir; std::getline(dirs, dir, ':');) {
        fs::path candidate = fs::path(dir.empty() ? "." : dir) / program;
        if (is_executable_file(candidate)) return candidate;
    }
    return std::nullopt;
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

// The shepherds (below) of the programs running now, in slots a signal
// handler can read (kill_running_programs). 0: a free slot.
constexpr int kShepherdSlots = 256;
std::atomic<pid_t> g_shepherds[kShepherdSlots];

int claim_shepherd_slot(pid_t shepherd) {
    for (int i = 0; i < kShepherdSlots; ++i) {
        pid_t expected = 0;
        if (g_shepherds[i].compare_exchange_strong(expected, shepherd)) return i;
    }
    return -1;  // more programs at once than slots: that one is only stopped by its run's end
}

void release_shepherd_slot(int slot) {
    if (slot >= 0) g_shepherds[slot].store(0);
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
    if (find_on_path(program)) return program;
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

std::string ProgramEnd::describe() const {
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
        case How::over_total_time:
            what = fmt::format("still running after {} s, its limit in all: killed", total_timeout_seconds);
            break;
        case How::stopped: what = "stopped by the harness"; break;
        case How::not_started: return fmt::format("cannot start: {}", error);
    }
    return stderr_tail.empty() ? what : fmt::format("{}; stderr: {}", what, stderr_tail);
}

namespace {

// ----------------------------------------------------------- the shepherd
//
// Each program runs under a shepherd: a process forked from this one that
// is a child subreaper (prctl PR_SET_CHILD_SUBREAPER), so every process the
// program leaves behind, even one that escaped its process group with
// setsid or setpgid, is re-parented to the shepherd, not to init. When the
// program exits, or when the harness sends SIGTERM, the shepherd kills the
// program's group and then every descendant it still has, reaps them, and
// reports how the program ended. Nothing the program started outlives it,
// and no leftover child can hold its standard output open.
//
// A subreaper, not a cgroup: it needs no privilege and no delegated cgroup
// tree, which an unprivileged user (a CI runner, a Slurm job) rarely has.
//
// The shepherd is forked from a process that may have threads, and never
// calls exec: it uses async-signal-safe system calls only (no allocation,
// no stdio, no locks), on what the parent prepared before the fork.

// What the shepherd reports on its status pipe, once, as it ends.
struct ShepherdReport {
    enum Kind : int { exited, signalled, not_started } kind = not_started;
    int code = 0;  // exit status, signal, or errno (not_started)
    int chdir_failed = 0;  // not_started: the working folder, not exec, failed
};

// Everything the shepherd and the program's exec need, made before the fork.
struct ShepherdPlan {
    const char* path = nullptr;  // the program's file
    char* const* argv = nullptr;
    const char* cwd = nullptr;   // nullptr: the harness's
    int stdin_fd = -1, stdout_fd = -1, stderr_fd = -1;
    int status_fd = -1;  // the status pipe's write end
};

volatile sig_atomic_t g_shepherded_group = 0;  // in the shepherd: the program's group, once started

extern "C" void shepherd_on_stop(int) {
    // The harness (or its death: PR_SET_PDEATHSIG) says stop: the program's
    // group dies now; what it left is swept up once the program is reaped.
    if (const pid_t g = g_shepherded_group; g > 0) ::kill(-g, SIGKILL);
}

void write_all(int fd, const void* data, std::size_t size) {
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = ::write(fd, p, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return;
        p += n;
        size -= static_cast<std::size_t>(n);
    }
}

// Kills and reaps every child the shepherd has, repeatedly (a dying child's
// own children are re-parented here), until it has none. The children are
// listed from /proc/self/task/<tid>/children (CONFIG_PROC_CHILDREN, in
// Debian's kernels); a kernel without it gets the program's group killed and
// the rest waited for, not killed.
void sweep_descendants() {
    const pid_t self = ::getpid();
    char children_file[64] = "/proc/self/task/";
    {
        char digits[16];
        int n = 0;
        for (pid_t v = self; v > 0; v /= 10) digits[n++] = static_cast<char>('0' + v % 10);
        std::size_t at = std::strlen(children_file);
        while (n > 0) children_file[at++] = digits[--n];
        std::memcpy(children_file + at, "/children", sizeof "/children");
    }
    const auto kill_listed = [&]() -> int {
        int killed = 0;
        const int fd = ::open(children_file, O_RDONLY | O_CLOEXEC);
        if (fd < 0) return -1;
        char text[4096];
        ssize_t n = 0;
        pid_t pid = 0;
        while ((n = ::read(fd, text, sizeof text)) > 0) {
            for (ssize_t i = 0; i < n; ++i) {
                if (text[i] >= '0' && text[i] <= '9') {
                    pid = pid * 10 + (text[i] - '0');
                } else if (pid > 0) {
                    ::kill(pid, SIGKILL);
                    ++killed;
                    pid = 0;
                }
            }
        }
        if (pid > 0) ::kill(pid, SIGKILL), ++killed;
        ::close(fd);
        return killed;
    };
    for (int round = 0; round < 10000; ++round) {
        if (kill_listed() < 0) {
            // No children file: wait for what is left (the program's group
            // is already dead; an escapee is waited for, not missed silently).
            while (::waitpid(-1, nullptr, 0) > 0 || errno == EINTR) {
            }
            return;
        }
        const pid_t reaped = ::waitpid(-1, nullptr, 0);
        if (reaped < 0 && errno == ECHILD) return;
    }
}

// Closes every descriptor but `keep` (sorted): the shepherd never execs, so
// close-on-exec does not close for it the pipes of the harness, among them
// other programs' standard input, which would then never end.
void close_all_but(const int (&keep)[4]) {
    unsigned int from = 0;
    for (const int fd : keep) {
        if (fd > static_cast<int>(from) && ::close_range(from, static_cast<unsigned int>(fd) - 1, 0) != 0) {
            for (int other = static_cast<int>(from); other < fd; ++other) ::close(other);
        }
        from = static_cast<unsigned int>(fd) + 1;
    }
    if (::close_range(from, ~0U, 0) != 0) {
        rlimit files{};
        ::getrlimit(RLIMIT_NOFILE, &files);
        for (rlim_t fd = from; fd < files.rlim_cur && fd < (1u << 20); ++fd) ::close(static_cast<int>(fd));
    }
}

[[noreturn]] void run_shepherd(const ShepherdPlan& plan, pid_t harness) {
    int keep[4] = {plan.stdin_fd, plan.stdout_fd, plan.stderr_fd, plan.status_fd};
    std::sort(std::begin(keep), std::end(keep));  // std::sort on four ints: no allocation
    close_all_but(keep);
    ::setpgid(0, 0);  // away from the terminal's Ctrl-C: the harness decides
    ::prctl(PR_SET_CHILD_SUBREAPER, 1);
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    // The harness's handlers are not the shepherd's: default for all, then its own.
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    for (int sig = 1; sig < NSIG; ++sig) ::sigaction(sig, &dfl, nullptr);
    struct sigaction stop {};
    stop.sa_handler = shepherd_on_stop;  // no SA_RESTART: waitid returns EINTR
    for (int sig : {SIGTERM, SIGINT, SIGHUP}) ::sigaction(sig, &stop, nullptr);
    ShepherdReport report;
    if (::getppid() != harness) {  // the harness died before PDEATHSIG was set
        write_all(plan.status_fd, &report, sizeof report);
        ::_exit(0);
    }

    int exec_pipe[2];
    if (::pipe2(exec_pipe, O_CLOEXEC) != 0) {
        report.code = errno;
        write_all(plan.status_fd, &report, sizeof report);
        ::_exit(0);
    }
    const pid_t program = ::fork();  // every signal is still blocked, as the parent left it
    if (program == 0) {
        ::setpgid(0, 0);  // its own group, without the shepherd: killing it spares the sweep
        // Above 2 first: a pipe end the harness got as descriptor 0, 1 or 2
        // (it was started with one closed) would be overwritten by a dup2.
        const int in = ::fcntl(plan.stdin_fd, F_DUPFD_CLOEXEC, 3), out = ::fcntl(plan.stdout_fd, F_DUPFD_CLOEXEC, 3),
                  err = ::fcntl(plan.stderr_fd, F_DUPFD_CLOEXEC, 3);
        ::dup2(in, STDIN_FILENO);
        ::dup2(out, STDOUT_FILENO);
        ::dup2(err, STDERR_FILENO);
        ::prctl(PR_SET_PDEATHSIG, 0);
        ShepherdReport failed;
        if (plan.cwd && ::chdir(plan.cwd) != 0) {
            failed.code = errno;
            failed.chdir_failed = 1;
        } else {
            sigset_t none;
            sigemptyset(&none);
            ::sigprocmask(SIG_SETMASK, &none, nullptr);
            ::execve(plan.path, plan.argv, environ);
            failed.code = errno;
        }
        write_all(exec_pipe[1], &failed, sizeof failed);
        ::_exit(127);
    }
    ::close(exec_pipe[1]);
    for (int fd : {plan.stdin_fd, plan.stdout_fd, plan.stderr_fd}) ::close(fd);  // only the program holds them
    if (program < 0) {
        report.code = errno;
        write_all(plan.status_fd, &report, sizeof report);
        ::_exit(0);
    }
    ::setpgid(program, program);  // also here: the harness's stop may come before the child's own call
    g_shepherded_group = program;
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);  // a stop that came meanwhile lands now

    // Exec either closes the pipe (started) or says why it did not.
    ShepherdReport exec_failure;
    ssize_t got = 0;
    while ((got = ::read(exec_pipe[0], &exec_failure, sizeof exec_failure)) < 0 && errno == EINTR) {
    }
    ::close(exec_pipe[0]);

    siginfo_t info{};
    while (::waitid(P_PID, static_cast<id_t>(program), &info, WEXITED | WNOWAIT) != 0 && errno == EINTR) {
    }
    sigset_t all;
    sigfillset(&all);
    ::sigprocmask(SIG_SETMASK, &all, nullptr);  // the sweep below kills everything anyway
    if (got == static_cast<ssize_t>(sizeof exec_failure)) {
        report = exec_failure;
    } else if (info.si_code == CLD_EXITED) {
        report.kind = ShepherdReport::exited;
        report.code = info.si_status;
    } else {
        report.kind = ShepherdReport::signalled;
        report.code = info.si_status;
    }
    ::kill(-program, SIGKILL);  // the group: still the program's until it is reaped below
    sweep_descendants();
    write_all(plan.status_fd, &report, sizeof report);
    ::_exit(0);
}

// The program's file as execve wants it: a name without '/' looked up on
// PATH as posix_spawnp does, or empty with the errno of the failure.
std::string exec_path(const std::string& program, int& error) {
    error = 0;
    if (program.find('/') != std::string::npos) return program;
    if (auto found = find_on_path(program)) return found->string();
    error = ENOENT;
    return {};
}

}  // namespace

namespace {

// A program started under its shepherd: the harness's ends of its pipes.
struct Launched {
    int in = -1, out = -1, err = -1, status = -1;  // its stdin, stdout, stderr, the shepherd's report
    pid_t shepherd = -1;
    int slot = -1;
    std::string err_tail;
};

// Starts `argv` in `cwd` under a shepherd; nothing, with `end.error`, if it cannot.
std::optional<Launched> launch(const std::vector<std::string>& argv_in, const fs::path& cwd, ProgramEnd& end) {
    if (argv_in.empty()) {
        end.error = "the command is empty";
        return std::nullopt;
    }
    int lookup_error = 0;
    const std::string path = exec_path(argv_in[0], lookup_error);
    if (path.empty()) {
        end.error = fmt::format("{}: {}", argv_in[0], std::strerror(lookup_error));
        return std::nullopt;
    }
    // Close-on-exec from birth: a program started by another thread at the
    // same time must not inherit these ends (it would hold our pipes open).
    Pipe in, out, err, status;
    for (Pipe* p : {&in, &out, &err, &status}) {
        int fds[2];
        if (::pipe2(fds, O_CLOEXEC) != 0) {
            end.error = fmt::format("pipe: {}", std::strerror(errno));
            for (Pipe* q : {&in, &out, &err, &status}) close_fd(q->read), close_fd(q->write);
            return std::nullopt;
        }
        *p = Pipe{fds[0], fds[1]};
    }
    std::vector<char*> argv;
    for (const std::string& a : argv_in) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const ShepherdPlan plan{path.c_str(), argv.data(), cwd.empty() ? nullptr : cwd.c_str(),
                            in.read, out.write, err.write, status.write};

    // Every signal blocked across the fork: the shepherd starts with none
    // delivered until it has its own handlers.
    sigset_t all, old;
    sigfillset(&all);
    ::pthread_sigmask(SIG_SETMASK, &all, &old);
    const pid_t harness = ::getpid();
    const pid_t shepherd = ::fork();
    if (shepherd == 0) run_shepherd(plan, harness);
    const int fork_error = errno;
    ::pthread_sigmask(SIG_SETMASK, &old, nullptr);
    close_fd(in.read);
    close_fd(out.write);
    close_fd(err.write);
    close_fd(status.write);
    if (shepherd < 0) {
        end.error = fmt::format("fork: {}", std::strerror(fork_error));
        for (int* fd : {&in.write, &out.read, &err.read, &status.read}) close_fd(*fd);
        return std::nullopt;
    }
    Launched launched{in.write, out.read, err.read, status.read, shepherd, claim_shepherd_slot(shepherd), {}};
    for (int fd : {launched.in, launched.out, launched.err}) ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
    return launched;
}

void drain_stderr(Launched& p) {
    char buffer[65536];
    for (;;) {
        const ssize_t n = ::read(p.err, buffer, sizeof buffer);
        if (n > 0) keep_tail(p.err_tail, {buffer, static_cast<std::size_t>(n)});
        else if (n < 0 && errno == EINTR) continue;
        else {
            if (n == 0) close_fd(p.err);
            return;
        }
    }
}

// An exchange's limits: no output for `silence_seconds`, or past `total`.
struct Deadlines {
    double silence_seconds;
    Clock::time_point silence, total;
    Deadlines(double silence_s, double total_s)
        : silence_seconds(silence_s), silence(deadline_after(silence_s)),
          total(total_s > 0 ? deadline_after(total_s) : Clock::time_point::max()) {}
    void heard() { silence = deadline_after(silence_seconds); }
    std::optional<ProgramEnd::How> passed() const {
        const auto now = Clock::now();
        if (now >= total) return ProgramEnd::How::over_total_time;
        if (now >= silence) return ProgramEnd::How::timed_out;
        return std::nullopt;
    }
    int millis_left() const { return millis_until(std::min(silence, total)); }
};

// One exchange with a launched program: writes `input` (then closes its
// standard input if `close_input`), passes its standard output on, keeps the
// tail of its standard error (a program blocked on a full stderr pipe would
// otherwise never finish), until its standard output ends (the program and
// everything it left are gone, or closed it), or `complete()` says the reply
// is whole after a piece of it. Returns why the harness cut it short, if it did.
std::optional<ProgramEnd::How> pump(Launched& p, std::string_view input, bool close_input,
                                    const std::function<bool(std::string_view)>& on_output,
                                    const std::function<bool()>& complete, Deadlines& limits,
                                    std::string& error) {
    const SigpipeHeld held;
    char buffer[65536];
    std::size_t written = 0;
    const auto input_done = [&] {
        if (close_input) close_fd(p.in);
    };
    if (input.empty()) input_done();
    while (p.out >= 0) {
        const bool writing = written < input.size() && p.in >= 0;
        pollfd fds[3] = {{writing ? p.in : -1, POLLOUT, 0}, {p.out, POLLIN, 0}, {p.err, POLLIN, 0}};
        const int ready = ::poll(fds, 3, limits.millis_left());
        if (ready < 0 && errno != EINTR) {
            error = fmt::format("poll: {}", std::strerror(errno));
            return ProgramEnd::How::stopped;
        }
        if (const auto cut = limits.passed()) return cut;
        if (ready <= 0) continue;
        if (fds[0].revents & (POLLOUT | POLLERR | POLLHUP)) {
            const ssize_t n = ::write(p.in, input.data() + written, input.size() - written);
            if (n > 0) written += static_cast<std::size_t>(n);
            // EPIPE: the program closed its input unread; what it does next decides.
            if (n < 0 && errno != EAGAIN && errno != EINTR) close_fd(p.in);
            else if (written == input.size()) input_done();
        }
        if (fds[2].revents & (POLLIN | POLLHUP | POLLERR)) drain_stderr(p);
        if (fds[1].revents & (POLLIN | POLLHUP | POLLERR)) {
            const ssize_t n = ::read(p.out, buffer, sizeof buffer);
            if (n > 0) {
                limits.heard();
                if (!on_output({buffer, static_cast<std::size_t>(n)})) return ProgramEnd::How::stopped;
                if (complete && complete()) return std::nullopt;
            } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
                close_fd(p.out);
            }
        }
    }
    return std::nullopt;
}

// Ends a launched program: its standard output has ended, or the harness
// cut the run (`cut`). Waits for the shepherd's report, which it writes once
// the program and all it left are reaped (within `limits`; once cut,
// it is told to stop, and killed if it has not within five seconds). Waited
// for on its pipe, not polled: a run costs no sleep.
void reap(Launched& p, std::optional<ProgramEnd::How> cut, const Deadlines& limits, const std::string& program,
          const fs::path& cwd, ProgramEnd& end) {
    close_fd(p.in);
    auto give_up = Clock::time_point::max();
    if (cut) ::kill(p.shepherd, SIGTERM), give_up = deadline_after(5);
    for (;;) {
        pollfd fds[2] = {{p.status, POLLIN, 0}, {p.err, POLLIN, 0}};
        const int wait_ms = cut ? millis_until(give_up) : limits.millis_left();
        if (::poll(fds, 2, wait_ms) < 0 && errno != EINTR) break;
        if (fds[1].revents & (POLLIN | POLLHUP | POLLERR)) drain_stderr(p);
        if (fds[0].revents & (POLLIN | POLLHUP | POLLERR)) break;  // the report, or the shepherd is gone
        if (!cut && (cut = limits.passed())) ::kill(p.shepherd, SIGTERM), give_up = deadline_after(5);
        if (Clock::now() >= give_up) {
            ::kill(p.shepherd, SIGKILL);
            break;
        }
    }
    ::fcntl(p.status, F_SETFL, ::fcntl(p.status, F_GETFL) | O_NONBLOCK);  // killed: no report to wait for
    ShepherdReport report;
    ssize_t got = 0;
    while ((got = ::read(p.status, &report, sizeof report)) < 0 && errno == EINTR) {
    }
    while (::waitpid(p.shepherd, nullptr, 0) < 0 && errno == EINTR) {
    }
    p.shepherd = -1;  // reaped: its pid may be another process's from now on
    release_shepherd_slot(p.slot);
    p.slot = -1;
    if (p.err >= 0) drain_stderr(p);
    close_fd(p.out);
    close_fd(p.err);
    close_fd(p.status);

    end.stderr_tail = last_lines(p.err_tail, 5);
    if (cut) {
        end.how = *cut;
    } else if (got != static_cast<ssize_t>(sizeof report)) {
        end.how = ProgramEnd::How::stopped;  // the shepherd died without a word
        end.error = "its supervising process ended without reporting";
    } else if (report.kind == ShepherdReport::not_started) {
        end.error = report.chdir_failed ? fmt::format("{}: {}", cwd.string(), std::strerror(report.code))
                                        : fmt::format("{}: {}", program, std::strerror(report.code));
    } else if (report.kind == ShepherdReport::signalled) {
        end.how = ProgramEnd::How::signalled;
        end.code = report.code;
    } else {
        end.how = ProgramEnd::How::exited;
        end.code = report.code;
    }
}

}  // namespace

ProgramEnd run_program(const ProgramRequest& request) {
    ProgramEnd end;
    end.silence_timeout_seconds = request.silence_timeout_seconds;
    end.total_timeout_seconds = request.total_timeout_seconds;
    auto launched = launch(request.argv, request.cwd, end);
    if (!launched) return end;
    Deadlines limits(request.silence_timeout_seconds, request.total_timeout_seconds);
    const auto cut = pump(*launched, request.input, /*close_input=*/true, request.on_output, {}, limits, end.error);
    reap(*launched, cut, limits, request.argv[0], request.cwd, end);
    return end;
}

struct ProgramSession::Running {
    Launched program;
    pid_t owner = ::getpid();
    std::string argv0;
    fs::path cwd;
};

std::unique_ptr<ProgramSession> ProgramSession::start(const std::vector<std::string>& argv, const fs::path& cwd,
                                                      std::string& why) {
    ProgramEnd end;
    auto launched = launch(argv, cwd, end);
    if (!launched) {
        why = end.error;
        return nullptr;
    }
    auto session = std::unique_ptr<ProgramSession>(new ProgramSession);
    session->running_ = std::make_unique<Running>(Running{std::move(*launched), ::getpid(), argv[0], cwd});
    return session;
}

ProgramSession::~ProgramSession() {
    if (!running_ || running_->owner != ::getpid()) {
        disown();
        return;
    }
    if (running_->program.shepherd < 0) return;  // an exchange already ended and reaped it
    // Its standard input closed, the program is told to stop; reap waits for
    // its shepherd's word that everything it started is gone.
    ProgramEnd end;
    reap(running_->program, ProgramEnd::How::stopped, Deadlines(5, 5), running_->argv0, running_->cwd, end);
}

std::optional<ProgramEnd> ProgramSession::exchange(std::string_view input,
                                                   const std::function<bool(std::string_view)>& on_output,
                                                   const std::function<bool()>& complete, double silence_seconds,
                                                   double total_seconds) {
    ProgramEnd end;
    end.silence_timeout_seconds = silence_seconds;
    end.total_timeout_seconds = total_seconds;
    Launched& p = running_->program;
    if (p.shepherd < 0 || p.out < 0) {
        end.how = ProgramEnd::How::stopped;
        end.error = "its session had already ended";
        return end;
    }
    Deadlines limits(silence_seconds, total_seconds);
    bool whole = false;
    const auto cut = pump(p, input, /*close_input=*/false, on_output, [&] { return whole = complete(); }, limits,
                          end.error);
    if (!cut && whole) return std::nullopt;
    reap(p, cut, limits, running_->argv0, running_->cwd, end);
    return end;
}

bool ProgramSession::running() const {
    if (!running_ || running_->owner != ::getpid() || running_->program.out < 0) return false;
    // The shepherd reports only when the program has ended.
    pollfd status{running_->program.status, POLLIN, 0};
    return ::poll(&status, 1, 0) == 0;
}

void ProgramSession::disown() {
    if (!running_) return;
    Launched& p = running_->program;
    for (int* fd : {&p.in, &p.out, &p.err, &p.status}) close_fd(*fd);
    // The slot array is this process's copy: the parent still holds its own.
    release_shepherd_slot(p.slot);
    running_.reset();
}

ProgramSession::ProgramSession() = default;

void kill_running_programs() {
    // Each shepherd kills its program's whole tree; the caller dies next,
    // and a shepherd finishes its sweep without it.
    for (std::atomic<pid_t>& shepherd : g_shepherds)
        if (const pid_t pid = shepherd.load(); pid > 0) ::kill(pid, SIGTERM);  // async-signal-safe
}

}  // namespace bouncecheck
