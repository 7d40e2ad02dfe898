// Running a simulator in a child process, so that an engine that aborts,
// asserts or crashes (Bullet and ODE assert on some inputs) costs only its
// own result: the parent records it as failed, with the signal, and goes on.
#pragma once

#include <functional>
#include <string>

namespace bouncecheck {

struct ChildResult {
    bool ok = false;
    std::string payload;  // what the child's work returned (when ok)
    std::string failure;  // why not: the signal or exit status, and the last lines the child wrote to stderr
};

// Forks; the child runs `work` and sends its returned bytes to the parent
// through a pipe, then exits without running the parent's exit handlers. An
// exception in the child is a failure with its message.
ChildResult run_in_child(const std::function<std::string()>& work);

}  // namespace bouncecheck
