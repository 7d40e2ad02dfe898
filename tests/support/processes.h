// Test helper: whether a process the test started (or one it started) is gone.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

namespace bouncecheck::test {

// Whether `pid` is gone (or a zombie: killed, not yet reaped by whoever
// holds it now, such as init), waiting up to two seconds.
inline bool dead(pid_t pid) {
    for (int i = 0; i < 100; ++i) {
        std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
        std::string line;
        if (!std::getline(stat, line) || line.substr(line.rfind(')') + 2, 1) == "Z") return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
}

}  // namespace bouncecheck::test
