#include "platform/parallel_pairs.h"

#include "platform/program.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

namespace bouncecheck {

namespace {

using Clock = std::chrono::steady_clock;
using Pair = std::pair<std::size_t, std::size_t>;  // (simulator, item)

// A result on the channel: its size (8 bytes), whether `run` returned (1 byte), the bytes.
constexpr std::size_t kHeader = sizeof(std::uint64_t) + 1;
constexpr std::size_t kStderrKept = 64 * 1024;

bool write_all(int fd, const char* data, std::size_t size, int flags) {
    while (size > 0) {
        const ssize_t n = ::send(fd, data, size, flags);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        data += n;
        size -= static_cast<std::size_t>(n);
    }
    return true;
}

bool read_exact(int fd, char* data, std::size_t size) {
    while (size > 0) {
        const ssize_t n = ::read(fd, data, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        data += n;
        size -= static_cast<std::size_t>(n);
    }
    return true;
}

// Ends a worker that overstayed: SIGTERM first, so that its interrupt
// handler kills the programs it runs and removes its temporary files,
// SIGKILL if it is still there a second later; then reaps it.
void terminate_worker(pid_t pid) {
    ::kill(pid, SIGTERM);
    const auto give_up = Clock::now() + std::chrono::seconds(1);
    int status = 0;
    pid_t gone = 0;
    while ((gone = ::waitpid(pid, &status, WNOHANG)) == 0 && Clock::now() < give_up)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (gone != 0) return;
    ::kill(pid, SIGKILL);
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
}

// The worker's life: a pair's index in, its result out, until the channel closes.
[[noreturn]] void serve(int channel, const std::vector<Pair>& pairs, const PairSchedule& schedule) {
    for (;;) {
        std::uint64_t task = 0;
        if (!read_exact(channel, reinterpret_cast<char*>(&task), sizeof task) || task >= pairs.size()) ::_exit(0);
        std::string payload;
        char returned = 1;
        try {
            payload = schedule.run(pairs[task].first, pairs[task].second);
        } catch (const std::exception& e) {
            payload = fmt::format("exception: {}", e.what());
            returned = 0;
        } catch (...) {
            payload = "unknown exception";
            returned = 0;
        }
        std::fflush(stdout);
        std::fflush(stderr);
        const std::uint64_t size = payload.size();
        std::string message(reinterpret_cast<const char*>(&size), sizeof size);
        message += returned;
        message += payload;
        if (!write_all(channel, message.data(), message.size(), 0)) ::_exit(4);
    }
}

struct Worker {
    pid_t pid = -1;     // -1: no process in this slot
    int channel = -1;   // a socket: pair indices to the worker, results back
    int errors = -1;    // the read end of the worker's stderr
    std::optional<std::size_t> task;  // the pair it runs now (index into the pairs)
    Clock::time_point started;
    std::string inbox, stderr_text;
};

void set_nonblocking(int fd) { ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK); }

class Pool {
public:
    Pool(const std::vector<Pair>& pairs, const PairSchedule& schedule, std::size_t size)
        : pairs_(pairs), schedule_(schedule), workers_(size) {}

    Pool(const Pool&) = delete;
    Pool& operator=(const Pool&) = delete;

    // Idle workers read EOF and exit; busy ones (only after an exception in
    // `finished`) are killed.
    ~Pool() {
        for (Worker& w : workers_) {
            if (w.pid < 0) continue;
            if (w.task) ::kill(w.pid, SIGKILL);
            close_fds(w);
            reap(w.pid);
        }
    }

    void run() {
        while (done_ < pairs_.size()) {
            for (Worker& w : workers_) {
                if (next_ >= pairs_.size()) break;
                if (w.pid < 0) start(w);
                if (w.pid >= 0 && !w.task) assign(w);
            }
            if (std::none_of(workers_.begin(), workers_.end(), [](const Worker& w) { return w.task.has_value(); })) {
                // No worker could be started: every remaining pair fails with the reason.
                while (next_ < pairs_.size()) end(next_++, {PairOutcome::Kind::crashed, {}, start_error_});
                break;
            }
            wait_for_news();
            for (Worker& w : workers_) {
                if (w.pid < 0) continue;
                drain_errors(w);
                read_results(w);
            }
            watch_deadlines();
        }
    }

private:
    void start(Worker& w) {
        int channel[2], errors[2];
        if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, channel) != 0) {
            start_error_ = fmt::format("cannot start a worker process: socketpair: {}", std::strerror(errno));
            return;
        }
        if (::pipe2(errors, O_CLOEXEC) != 0) {
            start_error_ = fmt::format("cannot start a worker process: pipe: {}", std::strerror(errno));
            ::close(channel[0]);
            ::close(channel[1]);
            return;
        }
        std::fflush(stdout);  // else buffered output would be written by both processes
        std::fflush(stderr);
        const pid_t parent = ::getpid();
        const pid_t pid = ::fork();
        if (pid < 0) {
            start_error_ = fmt::format("cannot start a worker process: fork: {}", std::strerror(errno));
            for (int fd : {channel[0], channel[1], errors[0], errors[1]}) ::close(fd);
            return;
        }
        if (pid == 0) {
            // A worker outlives no parent: SIGTERM runs its clean-up (programs, temporary files).
            ::prctl(PR_SET_PDEATHSIG, SIGTERM);
            if (::getppid() != parent) ::_exit(0);
            // The other workers' ends: a copy held here would keep them from seeing EOF.
            for (const Worker& other : workers_) {
                if (other.channel >= 0) ::close(other.channel);
                if (other.errors >= 0) ::close(other.errors);
            }
            ::close(channel[0]);
            ::close(errors[0]);
            ::dup2(errors[1], STDERR_FILENO);
            ::close(errors[1]);
            serve(channel[1], pairs_, schedule_);
        }
        ::close(channel[1]);
        ::close(errors[1]);
        set_nonblocking(channel[0]);
        set_nonblocking(errors[0]);
        w = Worker{};
        w.pid = pid;
        w.channel = channel[0];
        w.errors = errors[0];
    }

    void assign(Worker& w) {
        const std::uint64_t task = next_++;
        w.task = task;
        w.started = Clock::now();
        w.stderr_text.clear();
        w.inbox.clear();
        // MSG_NOSIGNAL: a worker that died since is noticed by its EOF, not by a SIGPIPE here.
        if (!write_all(w.channel, reinterpret_cast<const char*>(&task), sizeof task, MSG_NOSIGNAL)) died(w);
    }

    void wait_for_news() {
        std::vector<pollfd> fds;
        for (const Worker& w : workers_) {
            if (w.pid < 0) continue;
            fds.push_back({w.channel, POLLIN, 0});
            if (w.errors >= 0) fds.push_back({w.errors, POLLIN, 0});
        }
        int timeout_ms = -1;
        if (schedule_.deadline_seconds > 0) {
            const auto now = Clock::now();
            for (const Worker& w : workers_) {
                if (w.pid < 0 || !w.task) continue;
                const auto left = w.started + deadline() - now;
                const int ms = static_cast<int>(std::max<std::int64_t>(
                    0, std::chrono::ceil<std::chrono::milliseconds>(left).count()));
                timeout_ms = timeout_ms < 0 ? ms : std::min(timeout_ms, ms);
            }
        }
        while (::poll(fds.data(), fds.size(), timeout_ms) < 0 && errno == EINTR) {
        }
    }

    void drain_errors(Worker& w) {
        char buf[65536];
        while (w.errors >= 0) {
            const ssize_t n = ::read(w.errors, buf, sizeof buf);
            if (n > 0) {
                w.stderr_text.append(buf, static_cast<std::size_t>(n));
                if (w.stderr_text.size() > 2 * kStderrKept) w.stderr_text.erase(0, w.stderr_text.size() - kStderrKept);
            } else if (n < 0 && errno == EINTR) {
                continue;
            } else {
                if (n == 0) {
                    ::close(w.errors);
                    w.errors = -1;
                }
                break;  // EAGAIN: nothing more now
            }
        }
    }

    void read_results(Worker& w) {
        char buf[65536];
        bool gone = false;
        for (;;) {
            const ssize_t n = ::read(w.channel, buf, sizeof buf);
            if (n > 0) {
                w.inbox.append(buf, static_cast<std::size_t>(n));
                continue;
            }
            if (n < 0 && errno == EINTR) continue;
            gone = !(n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK));  // EOF or an error
            break;
        }
        take_result(w);
        if (gone) died(w);
    }

    // The pair's result, once the whole of it is in.
    void take_result(Worker& w) {
        if (!w.task || w.inbox.size() < kHeader) return;
        std::uint64_t size = 0;
        std::memcpy(&size, w.inbox.data(), sizeof size);
        if (w.inbox.size() < kHeader + size) return;
        const bool returned = w.inbox[sizeof size] != 0;
        std::string payload = w.inbox.substr(kHeader, size);
        w.inbox.erase(0, kHeader + size);
        if (returned && !w.stderr_text.empty()) std::fputs(w.stderr_text.c_str(), stderr);  // its warnings, passed on
        PairOutcome o;
        if (returned) {
            o.payload = std::move(payload);
        } else {
            o.kind = PairOutcome::Kind::crashed;
            o.failure = std::move(payload);
        }
        const std::size_t task = *w.task;
        w.task.reset();
        end(task, o);
    }

    // The worker's process is gone (or going): reap it and fail its pair.
    void died(Worker& w) {
        const int status = reap(w.pid);
        // What it wrote last may still be in the pipe; a grandchild holding
        // the pipe open must not keep us here.
        if (w.errors >= 0) {
            pollfd p{w.errors, POLLIN, 0};
            while (w.errors >= 0 && ::poll(&p, 1, 100) > 0) {
                const std::size_t before = w.stderr_text.size();
                drain_errors(w);
                if (w.errors >= 0 && w.stderr_text.size() == before) break;
            }
        }
        const std::string said = last_lines(w.stderr_text, 3);
        std::string why;
        if (WIFSIGNALED(status))
            why = fmt::format("signal {} ({})", WTERMSIG(status), ::strsignal(WTERMSIG(status)));
        else
            why = fmt::format("its worker process exited with status {}", WEXITSTATUS(status));
        if (!said.empty()) why += ": " + said;
        const std::optional<std::size_t> task = w.task;
        close_fds(w);
        w.pid = -1;
        w.task.reset();
        if (task) end(*task, {PairOutcome::Kind::crashed, {}, why});
    }

    void watch_deadlines() {
        if (schedule_.deadline_seconds <= 0) return;
        const auto now = Clock::now();
        for (Worker& w : workers_) {
            if (w.pid < 0 || !w.task || now - w.started < deadline()) continue;
            const double seconds = std::chrono::duration<double>(now - w.started).count();
            terminate_worker(w.pid);
            drain_errors(w);
            const std::string said = last_lines(w.stderr_text, 3);
            const std::size_t task = *w.task;
            close_fds(w);
            w.pid = -1;
            w.task.reset();
            end(task, {PairOutcome::Kind::hung, {},
                       fmt::format("no result after {:.3g} s, over the limit of {:.3g} s; its worker process "
                                   "was killed{}{}",
                                   seconds, schedule_.deadline_seconds, said.empty() ? "" : ": ", said)});
        }
    }

    void end(std::size_t task, const PairOutcome& o) {
        ++done_;
        if (schedule_.finished) schedule_.finished(pairs_[task].first, pairs_[task].second, o, done_, pairs_.size());
    }

    Clock::duration deadline() const {
        return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(schedule_.deadline_seconds));
    }

    static int reap(pid_t pid) {
        int status = 0;
        while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
        }
        return status;
    }

    static void close_fds(Worker& w) {
        for (int* fd : {&w.channel, &w.errors}) {
            if (*fd >= 0) ::close(*fd);
            *fd = -1;
        }
    }

    const std::vector<Pair>& pairs_;
    const PairSchedule& schedule_;
    std::vector<Worker> workers_;
    std::size_t next_ = 0, done_ = 0;
    std::string start_error_ = "cannot start a worker process";
};

// The cores this process may run on (a Slurm task's CPUs, taskset's), not every core of the machine.
std::size_t usable_cores() {
    cpu_set_t set;
    if (::sched_getaffinity(0, sizeof set, &set) == 0) return static_cast<std::size_t>(std::max(1, CPU_COUNT(&set)));
    return static_cast<std::size_t>(std::max(1L, ::sysconf(_SC_NPROCESSORS_ONLN)));
}

}  // namespace

void run_pairs_in_parallel(std::size_t simulators, std::size_t items, const PairSchedule& schedule) {
    std::vector<Pair> pairs;
    for (std::size_t sim = 0; sim < simulators; ++sim)
        for (std::size_t item = 0; item < items; ++item) pairs.emplace_back(sim, item);
    if (!schedule.shard.whole()) {
        std::vector<double> costs;
        for (const auto& [sim, item] : pairs) costs.push_back(schedule.cost(sim, item));
        const std::vector<int> shard_of = assign_shards(costs, schedule.shard.count);
        std::vector<Pair> mine;
        for (std::size_t i = 0; i < pairs.size(); ++i)
            if (shard_of[i] == schedule.shard.index) mine.push_back(pairs[i]);
        pairs = std::move(mine);
    }
    if (pairs.empty()) return;
    std::stable_sort(pairs.begin(), pairs.end(),
                     [&](const Pair& a, const Pair& b) {
                         return schedule.cost(a.first, a.second) > schedule.cost(b.first, b.second);
                     });
    const std::size_t jobs = schedule.jobs > 0 ? static_cast<std::size_t>(schedule.jobs) : usable_cores();
    Pool pool(pairs, schedule, std::min(jobs, pairs.size()));
    pool.run();
}

}  // namespace bouncecheck
