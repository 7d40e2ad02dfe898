#include "platform/bounded_read.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace bouncecheck {

std::variant<std::string, ReadRefusal> read_bounded(const std::filesystem::path& file, std::uintmax_t max_bytes,
                                                    Links links) {
    const int flags = O_RDONLY | O_NONBLOCK | O_CLOEXEC | (links == Links::refuse ? O_NOFOLLOW : 0);
    const int fd = ::open(file.c_str(), flags);
    if (fd < 0) {
        const int error = errno;
        if (error == ELOOP) return ReadRefusal{"not a regular file (a symbolic link)", false};
        return ReadRefusal{std::strerror(error), error == ENOENT};
    }
    struct stat info {};
    if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
        ::close(fd);
        return ReadRefusal{"not a regular file", false};
    }
    if (static_cast<std::uintmax_t>(info.st_size) > max_bytes) {
        ::close(fd);
        return ReadRefusal{fmt::format("{} bytes, over the limit of {}", info.st_size, max_bytes), false};
    }
    std::string bytes(static_cast<std::size_t>(info.st_size), '\0');
    std::size_t got = 0;
    while (got < bytes.size()) {
        const ssize_t n = ::read(fd, bytes.data() + got, bytes.size() - got);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;  // shorter than it was: what is there
        got += static_cast<std::size_t>(n);
    }
    ::close(fd);
    bytes.resize(got);
    return bytes;
}

}  // namespace bouncecheck
