// Running another program (an external simulator, docs/external.md): its
// standard input fed, its standard output streamed to the caller as it comes,
// a silence limit and an overall one, and nothing left behind: the program
// runs under a supervising process that is its subreaper, which kills and
// reaps every process the program started, even those that left its process
// group or session, when the program ends or the harness stops it.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bouncecheck {

// What to run for `program` (an argv[0]) wherever the run happens: a name
// without '/' stays as it is when PATH holds it; a path, taken relative to
// `base` when relative, becomes absolute, so that a run in another folder
// finds the same file. Nothing if there is no executable regular file there;
// `why` says what was looked at.
std::optional<std::string> resolve_program(const std::string& program, const std::filesystem::path& base,
                                           std::string* why = nullptr);

// The last `count` non-empty lines of `text`, joined by " | " (a child's
// standard error, for a failure's reason), made printable (printable_text).
std::string last_lines(std::string_view text, std::size_t count);

struct ProgramRequest {
    std::vector<std::string> argv;  // argv[0] is looked up on PATH unless it holds a '/'
    std::filesystem::path cwd;      // empty: this process's
    std::string input;              // written to standard input, which is then closed
    // Each piece of standard output as it arrives; returning false ends the
    // run (the program is killed).
    std::function<bool(std::string_view)> on_output;
    double silence_timeout_seconds = 600;  // no standard output for this long: killed
    double total_timeout_seconds = 0;      // running this long in all: killed; 0: no limit
};

struct ProgramEnd {
    // timed_out: silent too long; over_total_time: ran too long in all.
    enum class How { exited, signalled, timed_out, over_total_time, stopped, not_started } how = How::not_started;
    int code = 0;             // exit status, or the signal
    std::string error;        // not_started: why
    std::string stderr_tail;  // the last lines of its standard error (last_lines)
    double silence_timeout_seconds = 0, total_timeout_seconds = 0;  // the request's limits

    bool succeeded() const { return how == How::exited && code == 0; }
    // "exit status 3", "killed by signal 11 (Segmentation fault)", ... with
    // the last lines of standard error; empty when it succeeded.
    std::string describe() const;
};

// Runs the program to its end: until it and every process it started are
// gone. Blocks; safe to call from several threads at once (every descriptor
// is close-on-exec, SIGPIPE is held off in the calling thread only).
ProgramEnd run_program(const ProgramRequest& request);

// A program kept running across several exchanges (docs/external.md,
// Sessions), under the same shepherd as run_program's: each exchange writes
// a request to its standard input, which stays open, and reads its reply.
// A session belongs to the process that started it: in a forked child it is
// neither used nor stopped (disown), and the parent's stays whole.
class ProgramSession {
public:
    // Starts `argv` in `cwd`; nothing, with `why`, if it cannot start (a
    // program whose exec fails is seen at the first exchange).
    static std::unique_ptr<ProgramSession> start(const std::vector<std::string>& argv,
                                                 const std::filesystem::path& cwd, std::string& why);
    // Closes its standard input and stops it with everything it started.
    ~ProgramSession();
    ProgramSession(const ProgramSession&) = delete;
    ProgramSession& operator=(const ProgramSession&) = delete;

    // Writes `input`, then passes each piece of standard output to
    // `on_output` (false: stop) until `complete()`, asked after each piece,
    // says the reply is whole: nothing is returned, and the session goes
    // on. Otherwise the program ended, or was stopped at a limit or by
    // `on_output`: how it ended is returned, and the session is over.
    std::optional<ProgramEnd> exchange(std::string_view input, const std::function<bool(std::string_view)>& on_output,
                                       const std::function<bool()>& complete, double silence_seconds,
                                       double total_seconds);
    // Still running, as far as can be seen without waiting, and this process's.
    bool running() const;
    // Forgets the program without stopping it: this process's copy of the
    // session, in a forked child, while the parent keeps the program.
    void disown();

private:
    ProgramSession();
    struct Running;
    std::unique_ptr<Running> running_;
};

// Stops every program run_program is running, with everything it started.
// Async-signal-safe: the interrupt handler (atomic_file.h) calls it, so that
// a Ctrl-C does not leave a program running that the terminal's signal never
// reached (it runs in a group of its own).
void kill_running_programs();

}  // namespace bouncecheck
