#include "platform/isolation.h"

#include "platform/program.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <vector>

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

namespace bouncecheck {

namespace {

void write_all(int fd, const std::string& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) ::_exit(4);
        done += static_cast<std::size_t>(n);
    }
}

}  // namespace

ChildResult run_in_child(const std::function<std::string()>& work) {
    int out[2], err[2];
    if (::pipe(out) != 0) return {false, {}, fmt::format("cannot isolate: pipe: {}", std::strerror(errno))};
    if (::pipe(err) != 0) {
        ::close(out[0]);
        ::close(out[1]);
        return {false, {}, fmt::format("cannot isolate: pipe: {}", std::strerror(errno))};
    }
    // Buffered output would otherwise be written twice, by both processes.
    std::fflush(stdout);
    std::fflush(stderr);
    const pid_t pid = ::fork();
    if (pid < 0) {
        for (int fd : {out[0], out[1], err[0], err[1]}) ::close(fd);
        return {false, {}, fmt::format("cannot isolate: fork: {}", std::strerror(errno))};
    }
    if (pid == 0) {
        ::close(out[0]);
        ::close(err[0]);
        ::dup2(err[1], STDERR_FILENO);
        int code = 0;
        std::string payload;
        try {
            payload = work();
        } catch (const std::exception& e) {
            std::fprintf(stderr, "exception: %s\n", e.what());
            code = 3;
        }
        std::fflush(stdout);
        std::fflush(stderr);
        write_all(out[1], payload);
        ::_exit(code);  // not exit(): the parent's atexit handlers and static destructors are the parent's
    }
    ::close(out[1]);
    ::close(err[1]);

    // Both pipes at once: a child filling its stderr must not block on a
    // parent waiting for its payload.
    ChildResult result;
    std::string errors;
    pollfd fds[2] = {{out[0], POLLIN, 0}, {err[0], POLLIN, 0}};
    std::string* sinks[2] = {&result.payload, &errors};
    int open_fds = 2;
    char buf[65536];
    while (open_fds > 0) {
        if (::poll(fds, 2, -1) < 0) {
            if (errno == EINTR) continue;
            break;
        }
        for (int i = 0; i < 2; ++i) {
            if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
            const ssize_t n = ::read(fds[i].fd, buf, sizeof buf);
            if (n > 0) {
                sinks[i]->append(buf, static_cast<std::size_t>(n));
            } else if (n == 0 || errno != EINTR) {
                ::close(fds[i].fd);
                fds[i].fd = -1;
                --open_fds;
            }
        }
    }
    for (const pollfd& p : fds)
        if (p.fd >= 0) ::close(p.fd);

    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    const std::string said = last_lines(errors, 3);
    if (WIFSIGNALED(status)) {
        result.failure = fmt::format("crashed: signal {} ({}){}{}", WTERMSIG(status), ::strsignal(WTERMSIG(status)),
                                     said.empty() ? "" : ": ", said);
    } else if (WIFEXITED(status) && WEXITSTATUS(status) != 0) {
        result.failure = said.empty() ? fmt::format("exit status {}", WEXITSTATUS(status)) : said;
    } else {
        result.ok = true;
        if (!errors.empty()) std::fputs(errors.c_str(), stderr);  // the child's warnings, passed on
    }
    return result;
}

}  // namespace bouncecheck
