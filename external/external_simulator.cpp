#include "external/external_simulator.h"

#include "external/trajectory_reader.h"
#include "platform/atomic_file.h"
#include "platform/bounded_read.h"
#include "platform/printable_text.h"
#include "platform/program.h"
#include "simulators/stream_contacts.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <unistd.h>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

using nlohmann::json;

json vector_json(const Vec3& v, int dim) {
    json out = json::array();
    for (int i = 0; i < dim; ++i) out.push_back(v[i]);
    return out;
}

// An empty file the program may write its settings to, removed with this,
// and by the interrupt handler when a signal ends the run first (Ctrl-C, or
// the stress watchdog's SIGTERM to a worker that overstays).
class SettingsFile {
public:
    SettingsFile() : path_(make()), removed_on_interrupt_(path_) {}
    ~SettingsFile() {
        std::error_code ec;
        fs::remove(path_, ec);
    }
    const std::string& path() const { return path_; }
    // What the program wrote there. The program may have put anything in
    // its place: a FIFO (opened without waiting, then refused), a link to
    // /dev/zero or a huge file (refused from its size, before reading).
    std::string read() const {
        auto read = read_bounded(path_, kMaxExternalSettingsBytes, Links::refuse);
        if (auto* refused = std::get_if<ReadRefusal>(&read)) {
            if (refused->missing) return {};  // removed: no settings
            throw std::runtime_error(refused->reason);
        }
        return std::get<std::string>(std::move(read));
    }

private:
    static std::string make() {
        std::string pattern = (fs::temp_directory_path() / "bouncecheck-settings-XXXXXX").string();
        const int fd = ::mkstemp(pattern.data());
        if (fd < 0) throw std::runtime_error(fmt::format("cannot create a settings file in {}", pattern));
        ::close(fd);
        return pattern;
    }

    std::string path_;
    RemovedOnInterrupt removed_on_interrupt_;
};

// Streams rows into a RunSink: each one with the contacts seen since the
// previous one. Remembers whether the sink said stop (the recorder's
// verdict on a state then stands, not the program's).
class RowsToSink {
public:
    RowsToSink(const Scenario& s, RunSink& sink) : detector_(s), sink_(sink) {}
    bool operator()(const State& state) {
        const ContactMask contact = first_ ? ContactMask{} : detector_.detect<3>(previous_, state);
        first_ = false;
        previous_ = state;
        stopped_ = !sink_.on_state(state, contact);
        return !stopped_;
    }
    bool stopped() const { return stopped_; }

private:
    StreamContactDetector detector_;
    RunSink& sink_;
    State previous_;
    bool first_ = true, stopped_ = false;
};

RunOutcome failed(RunOutcome out, std::string reason) {
    out.status = RunStatus::failed;
    out.reason = std::move(reason);
    return out;
}

// The idle sessions of one session program, each ready for its next
// scenario, by working folder. Only this process's are used: a worker
// forked from it leaves the parent's alone (ProgramSession::disown).
class SessionPool {
public:
    std::unique_ptr<ProgramSession> take(const fs::path& cwd) {
        const std::lock_guard lock(mutex_);
        std::unique_ptr<ProgramSession> found;
        // A session that is not running here (it ended meanwhile, or it is
        // a forked copy of the parent's) is dropped: its destructor reaps
        // it, or disowns the copy.
        for (auto it = idle_.begin(); it != idle_.end();) {
            if (!it->second->running()) {
                it = idle_.erase(it);
            } else if (!found && it->first == cwd) {
                found = std::move(it->second);
                it = idle_.erase(it);
            } else {
                ++it;
            }
        }
        return found;
    }
    void give_back(const fs::path& cwd, std::unique_ptr<ProgramSession> session) {
        const std::lock_guard lock(mutex_);
        idle_.emplace(cwd, std::move(session));
    }

private:
    std::mutex mutex_;
    std::multimap<fs::path, std::unique_ptr<ProgramSession>> idle_;
};

class ExternalSimulator final : public Simulator {
public:
    ExternalSimulator(ExternalDeclaration d, ExternalLimits limits)
        : declaration_(std::move(d)), limits_(limits),
          origin_(declaration_.origin.empty() ? fmt::format("external: {}", fmt::join(declaration_.command, " "))
                                              : declaration_.origin) {}

    std::string_view name() const override { return declaration_.name; }
    std::string_view description() const override { return origin_; }
    std::string_view origin() const override { return origin_; }

    RunOutcome run(const Scenario& s, RunSink& sink) const override {
        RunOutcome out;
        out.settings.push_back({"protocol", fmt::format("bouncecheck-external/{}", kExternalProtocol),
                                "docs/external.md: the scenario on stdin as JSON, the trajectory on stdout as CSV "
                                "rows or binary blocks"});
        const SettingsFile settings;
        TrajectoryReader reader(s);
        RowsToSink rows(s, sink);
        const std::string input =
            external_input(s, declaration_.name, settings.path(), declaration_.builtin_engine);
        const auto on_output = [&](std::string_view bytes) { return reader.feed(bytes, rows); };
        ProgramEnd end;
        if (declaration_.session) {
            out.run_seconds = timed_seconds([&] { end = exchange(s.source.parent_path(), input, on_output, reader); });
        } else {
            ProgramRequest request;
            request.argv = declaration_.command;
            request.cwd = s.source.parent_path();
            request.input = input;
            request.on_output = on_output;
            request.silence_timeout_seconds = limits_.silence_seconds;
            request.total_timeout_seconds = limits_.total_seconds;
            out.run_seconds = timed_seconds([&] { end = run_program(request); });
        }

        if (rows.stopped()) return out;
        const auto with_stderr = [&](const std::string& what) {
            return end.stderr_tail.empty() ? what : fmt::format("{}; stderr: {}", what, end.stderr_tail);
        };
        if (reader.problem()) return failed(out, with_stderr("malformed trajectory: " + reader.problem()->format()));
        // A session's reply ends with #end: without it, the harness waits on
        // a program that waits for its next scenario, until a limit.
        if (declaration_.session && !reader.ended() && reader.rows() == reader.expected_rows())
            return failed(out, fmt::format("every row came, but no #end line after them: a session's reply must end "
                                           "with one (docs/external.md, Sessions); {}",
                                           end.succeeded() ? "the program then exited" : end.describe()));
        if (!end.succeeded()) return failed(out, end.describe());
        if (!reader.finish(rows)) {
            if (rows.stopped()) return out;
            return failed(out, with_stderr("malformed trajectory: " + reader.problem()->format()));
        }
        // The program's own measure of its engine's steps: it cannot exceed
        // the whole run as the harness timed it (start-up included). One
        // that does is shown, not used: a timing slip costs no result.
        if (const auto step = reader.step_seconds(); step && *step <= out.run_seconds) {
            out.step_seconds = step;
        } else if (step) {
            out.settings.push_back({"step_seconds", fmt::format("{:g} s, ignored", *step),
                                    fmt::format("the #end line's step time is more than the whole run's {:g} s", out.run_seconds)});
        }
        try {
            const std::string text = settings.read();
            if (!text.empty())
                for (Setting& st : parse_external_settings(text)) out.settings.push_back(std::move(st));
        } catch (const std::exception& e) {
            return failed(out, fmt::format("its settings file: {}", e.what()));
        }
        return out;
    }

private:
    // One scenario through a session: an idle one of this process, or a new
    // one. A whole reply keeps the session for the next scenario; anything
    // else has ended it (ProgramSession::exchange), and the row is judged
    // as a one-shot program's would be.
    ProgramEnd exchange(const fs::path& cwd, const std::string& input,
                        const std::function<bool(std::string_view)>& on_output, const TrajectoryReader& reader) const {
        std::unique_ptr<ProgramSession> session = sessions_.take(cwd);
        bool reused = session != nullptr;
        for (;;) {
            if (!session) {
                ProgramEnd not_started;
                if (!(session = ProgramSession::start(declaration_.command, cwd, not_started.error))) return not_started;
            }
            auto ended = session->exchange(input, on_output, [&] { return reader.ended(); }, limits_.silence_seconds,
                                           limits_.total_seconds);
            // An idle session that ended between its last reply and this
            // request (its program exited after answering) is not this
            // scenario's failure: a new one takes the scenario.
            if (ended && reused && reader.rows() == 0 && !reader.problem()) {
                session.reset();
                reused = false;
                continue;
            }
            if (ended) return *ended;
            sessions_.give_back(cwd, std::move(session));
            ProgramEnd whole;
            whole.how = ProgramEnd::How::exited;
            return whole;
        }
    }

    ExternalDeclaration declaration_;
    ExternalLimits limits_;
    std::string origin_;
    mutable SessionPool sessions_;
};

class ImportedTrajectory final : public Simulator {
public:
    ImportedTrajectory(std::string name, std::string file)
        : name_(std::move(name)), file_(std::move(file)), origin_(fmt::format("imported: {}", file_)) {}

    std::string_view name() const override { return name_; }
    std::string_view description() const override { return origin_; }
    std::string_view origin() const override { return origin_; }

    RunOutcome run(const Scenario& s, RunSink& sink) const override {
        RunOutcome out;
        out.settings.push_back({"file", file_, "a recorded trajectory, compared as it was recorded"});
        RowsToSink rows(s, sink);
        std::optional<std::string> problem;
        out.run_seconds = timed_seconds([&] { problem = read_trajectory_file(file_, s, std::ref(rows)); });
        if (problem) return failed(out, *problem);
        return out;
    }

private:
    std::string name_, file_, origin_;
};

}  // namespace

std::unique_ptr<const Simulator> make_external_simulator(ExternalDeclaration declaration, ExternalLimits limits) {
    return std::make_unique<ExternalSimulator>(std::move(declaration), limits);
}

std::unique_ptr<const Simulator> make_imported_trajectory(std::string name, std::string file) {
    return std::make_unique<ImportedTrajectory>(std::move(name), std::move(file));
}

namespace {

// A built-in engine's [engines.NAME]: its own keys as written, and the
// shared options as the harness read them (defaults filled in).
json builtin_engine_table(const Scenario& s, const std::string& name) {
    const auto own = s.passthrough_tables.find(name);
    json table = own == s.passthrough_tables.end() ? json::object() : json::parse(own->second);
    const EngineOptions options = s.engine_options(name);
    table["tangential_model"] = options.tangential_model == TangentialModel::per_contact ? "per-contact" : "friction";
    table["friction"] = options.friction;
    table["rotation"] = options.free_rotation ? "free" : "locked";
    table["substeps"] = options.substeps;
    if (options.ccd) table["ccd"] = *options.ccd;
    return table;
}

}  // namespace

std::string external_input(const Scenario& s, const std::string& name, const std::string& settings_file,
                           bool builtin_engine) {
    const auto table = s.passthrough_tables.find(name);
    json engine = builtin_engine                       ? builtin_engine_table(s, name)
                  : table == s.passthrough_tables.end() ? json::object()
                                                        : json::parse(table->second);
    const json j = {
        {"protocol", kExternalProtocol},
        {"scenario", s.name},
        {"dimension", s.dim},
        {"room", vector_json(s.room, s.dim)},
        {"radius", s.radius},
        {"position", vector_json(s.position, s.dim)},
        {"velocity", vector_json(s.velocity, s.dim)},
        {"gravity", vector_json(s.gravity, s.dim)},
        {"alpha", s.alpha},
        {"beta", s.beta},
        {"dt", s.dt},
        {"duration", s.duration},
        {"steps", document_step_count(s.dt, s.duration)},
        {"engine", std::move(engine)},
        {"settings_file", settings_file},
    };
    return j.dump(-1, ' ', false, json::error_handler_t::replace) + "\n";  // a path may not be UTF-8
}

std::vector<Setting> parse_external_settings(const std::string& text) {
    if (text.size() > kMaxExternalSettingsBytes)
        throw std::runtime_error(fmt::format("{} bytes, over the limit of {}", text.size(), kMaxExternalSettingsBytes));
    // An array of flat objects: anything nested deeper is refused as it is read.
    const json::parser_callback_t depth_limit = [](int depth, json::parse_event_t, json&) {
        if (depth > kMaxExternalSettingsDepth)
            throw std::runtime_error(fmt::format("nested deeper than {} levels", kMaxExternalSettingsDepth));
        return true;
    };
    const json j = json::parse(text, depth_limit, /*allow_exceptions=*/false);
    if (j.is_discarded()) throw std::runtime_error("not valid JSON");
    if (!j.is_array()) throw std::runtime_error("expected a JSON array of {\"key\", \"value\", \"why\"} objects");
    std::vector<Setting> settings;
    for (std::size_t i = 0; i < j.size(); ++i) {
        const json& item = j[i];
        const auto bad = [&](const char* why) { return std::runtime_error(fmt::format("entry {}: {}", i, why)); };
        if (!item.is_object()) throw bad("not an object");
        if (!item.contains("key") || !item["key"].is_string() || item["key"].get<std::string>().empty())
            throw bad("\"key\" must be a non-empty string");
        if (!item.contains("value")) throw bad("no \"value\"");
        const json& value = item["value"];
        if (!value.is_string() && !value.is_number() && !value.is_boolean())
            throw bad("\"value\" must be a string, a number or a boolean");
        if (item.contains("why") && !item["why"].is_string()) throw bad("\"why\" must be a string");
        // Shown on the terminal and in report.md: no escape sequence gets through.
        settings.push_back({printable_text(item["key"].get<std::string>()),
                            printable_text(value.is_string() ? value.get<std::string>() : value.dump()),
                            printable_text(item.value("why", std::string()))});
    }
    return settings;
}

}  // namespace bouncecheck
