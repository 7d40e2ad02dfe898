// Test helper: runs the built `bouncecheck` binary as a user or CI script
// would, and reads the files it writes.
#pragma once

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace bouncecheck::test {

struct CliResult {
    int status = -1;     // exit status, -1 if it did not exit normally
    std::string output;  // stdout and stderr together
};

inline CliResult bouncecheck(const std::string& args) {
    const std::string cmd = std::string(BOUNCECHECK_CLI) + " " + args + " 2>&1";
    CliResult r;
    FILE* pipe = ::popen(cmd.c_str(), "r");
    if (!pipe) return r;
    char buf[4096];
    for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) r.output.append(buf, n);
    const int raw = ::pclose(pipe);
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    return r;
}

inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

}  // namespace bouncecheck::test
