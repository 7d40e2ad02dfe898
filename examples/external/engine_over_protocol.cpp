// bouncecheck-external-engine ENGINE: one of bouncecheck's built simulators
// (`ode`, `bullet`, ..., also `reference`) run as an external simulator, over
// protocol bouncecheck-external/1 (docs/external.md):
//
//   bouncecheck run --engines ode --external 'ode-ext=/abs/path/bouncecheck-external-engine ode'
//
// Its trajectory is bit for bit the built-in adapter's, so the difference in
// run time between `ode` and `ode-ext` is what the protocol costs: a process
// (most of it: this one loads every engine's shared libraries at start-up),
// a pipe, and formatting and parsing every number.
//
// It reads the scenario as JSON on stdin, builds a bouncecheck::Scenario from
// it (the `engine` table, the scenario's [engines.NAME], gives the engine's
// options), runs the simulator with a RunSink that writes each state as a CSV
// row to stdout, exactly as `--trajectories` writes it, and writes the
// simulator's settings to `settings_file`.
#include "registry/registry.h"
#include "scenarios/scenario.h"
#include "simulators/simulator.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

using namespace bouncecheck;
using nlohmann::json;

namespace {

// The `dim` components of the vector `key`; the rest stay zero.
Vec3 vector_of(const json& in, const char* key, int dim) {
    const json& a = in.at(key);
    if (!a.is_array() || static_cast<int>(a.size()) != dim)
        throw std::runtime_error(fmt::format("\"{}\" must be an array of {} numbers", key, dim));
    Vec3 v = Vec3::Zero();
    for (int i = 0; i < dim; ++i) v[i] = a[i].get<double>();
    return v;
}

// The keys of [engines.<name>] that scenarios/loader.cpp reads; other keys are ignored.
EngineOptions engine_options(const json& table) {
    if (!table.is_object()) throw std::runtime_error("\"engine\" must be an object");
    EngineOptions o;
    if (table.contains("tangential_model")) {
        const auto model = table.at("tangential_model").get<std::string>();
        if (model == "friction") o.tangential_model = TangentialModel::friction;
        else if (model == "per-contact") o.tangential_model = TangentialModel::per_contact;
        else throw std::runtime_error("engine.tangential_model must be \"friction\" or \"per-contact\"");
    }
    if (table.contains("friction")) o.friction = table.at("friction").get<double>();
    if (table.contains("rotation")) {
        const auto rotation = table.at("rotation").get<std::string>();
        if (rotation != "free" && rotation != "locked")
            throw std::runtime_error("engine.rotation must be \"free\" or \"locked\"");
        o.free_rotation = rotation == "free";
    }
    if (table.contains("ccd")) o.ccd = table.at("ccd").get<bool>();
    if (table.contains("substeps")) {
        o.substeps = table.at("substeps").get<int>();
        if (o.substeps < 1) throw std::runtime_error("engine.substeps must be >= 1");
    }
    return o;
}

Scenario scenario_from(const json& in, const std::string& engine) {
    if (in.value("protocol", 0) != 1) throw std::runtime_error("expected \"protocol\": 1");
    Scenario s;
    s.name = in.at("scenario").get<std::string>();
    s.dim = in.at("dimension").get<int>();
    if (s.dim != 2 && s.dim != 3) throw std::runtime_error("\"dimension\" must be 2 or 3");
    s.room = vector_of(in, "room", s.dim);
    s.position = vector_of(in, "position", s.dim);
    s.velocity = vector_of(in, "velocity", s.dim);
    s.gravity = vector_of(in, "gravity", s.dim);
    s.radius = in.at("radius").get<double>();
    s.alpha = in.at("alpha").get<double>();
    s.beta = in.at("beta").get<double>();
    s.dt = in.at("dt").get<double>();
    s.duration = in.at("duration").get<double>();
    s.engines[engine] = engine_options(in.value("engine", json::object()));
    return s;
}

// Each state as a row of `--trajectories` CSV (reports/trajectory_csv.cpp),
// buffered and written to stdout in chunks of about 64 KiB.
class CsvToStdout final : public RunSink {
public:
    explicit CsvToStdout(int dim) : dim_(dim) { buffer_ = dim == 2 ? "t,x,y,vx,vy\n" : "t,x,y,z,vx,vy,vz\n"; }

    bool on_state(const State& s, ContactMask) override { return write(s); }
    // A simulator whose states have become periodic hands over the rest of
    // the run at once (the reference at rest): every one of them is a row.
    void on_periodic_tail(const PeriodicTail& tail) override {
        for (PeriodicTail::Cursor at(tail); at.left() > 0;)
            if (!write(at.next())) return;
    }

    // Writes what is left and the #end line with the steps' time; throws if stdout failed.
    void end(double step_seconds) {
        buffer_ += fmt::format("#end {{\"step_seconds\": {}}}\n", step_seconds);
        flush();
        if (std::fflush(stdout) != 0) throw std::runtime_error("cannot write to standard output");
        if (!failure_.empty()) throw std::runtime_error(failure_);
    }
    std::int64_t rows() const { return rows_; }
    // Time spent here, printing: the run's time less this is its steps'.
    double seconds_writing() const { return std::chrono::duration<double>(writing_).count(); }

private:
    bool write(const State& s) {
        const auto started = std::chrono::steady_clock::now();
        const bool more = write_row(s);
        writing_ += std::chrono::steady_clock::now() - started;
        return more;
    }
    bool write_row(const State& s) {
        if (!failure_.empty()) return false;
        for (int i = 0; i < dim_; ++i) {
            if (!std::isfinite(s.p[i]) || !std::isfinite(s.v[i])) {  // the protocol takes finite numbers only
                failure_ = fmt::format("non-finite state at t = {:.17g}", s.t);
                return false;
            }
        }
        // std::to_chars: the shortest text that reads back to the same double,
        // and the fastest way to print one here (about 75 ns, against 130 ns
        // for fmt's "{}" and 230 ns for "{:.17g}"; a row prints seven).
        char row[7 * 32];
        char* at = std::to_chars(row, row + 32, s.t).ptr;
        for (int i = 0; i < dim_; ++i) *at++ = ',', at = std::to_chars(at, at + 31, s.p[i]).ptr;
        for (int i = 0; i < dim_; ++i) *at++ = ',', at = std::to_chars(at, at + 31, s.v[i]).ptr;
        *at++ = '\n';
        buffer_.append(row, at);
        ++rows_;
        if (buffer_.size() >= kChunk) flush();
        return failure_.empty();
    }
    void flush() {
        if (std::fwrite(buffer_.data(), 1, buffer_.size(), stdout) != buffer_.size())
            failure_ = "cannot write to standard output (the harness stopped reading)";
        buffer_.clear();
    }

    static constexpr std::size_t kChunk = 64 * 1024;
    int dim_;
    std::string buffer_;
    std::int64_t rows_ = 0;
    std::string failure_;
    std::chrono::steady_clock::duration writing_{};
};

// The settings file: an array of {key, value, why} (docs/external.md, Settings).
void write_settings(const std::string& path, const std::string& engine, const std::vector<Setting>& settings) {
    json out = json::array();
    out.push_back({{"key", "protocol_wrapper"},
                   {"value", "bouncecheck-external-engine " + engine},
                   {"why", "bouncecheck's built-in adapter run over bouncecheck-external/1, to measure its cost"}});
    for (const Setting& s : settings) {
        json entry = {{"key", s.key}, {"value", s.value}};
        if (!s.why.empty()) entry["why"] = s.why;
        out.push_back(entry);
    }
    std::ofstream file(path);
    file << out.dump(1) << '\n';
    if (!file.flush()) throw std::runtime_error("cannot write the settings file " + path);
}

int run(const std::string& engine) {
    const json in = json::parse(std::cin);
    const Scenario s = scenario_from(in, engine);

    std::unique_ptr<const Simulator> sim;
    std::string known;
    for (auto& candidate : built_simulators()) {
        known += (known.empty() ? "" : ", ") + std::string(candidate->name());
        if (candidate->name() == engine) sim = std::move(candidate);
    }
    if (!sim) throw std::runtime_error(fmt::format("no built simulator \"{}\" (built: {})", engine, known));
    if (const auto why = sim->cannot_run(s)) throw std::runtime_error(fmt::format("{} cannot run this scenario: {}", engine, *why));

    CsvToStdout sink(s.dim);
    const auto started = std::chrono::steady_clock::now();
    const RunOutcome outcome = sim->run(s, sink);
    const double run_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (outcome.status != RunStatus::ok)
        throw std::runtime_error(fmt::format("{} {}: {}", engine, to_string(outcome.status), outcome.reason));
    const std::int64_t steps = in.at("steps").get<std::int64_t>();
    if (sink.rows() != steps + 1)
        throw std::runtime_error(fmt::format("{} rows written, steps + 1 = {} expected", sink.rows(), steps + 1));
    // The engine's steps alone (the run less its printing), so that the
    // harness charges the engine, not this wrapper's start-up or its rows.
    sink.end(std::max(0.0, run_seconds - sink.seconds_writing()));

    if (const auto path = in.find("settings_file"); path != in.end() && path->is_string())
        write_settings(path->get<std::string>(), engine, outcome.settings);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: bouncecheck-external-engine ENGINE   (scenario JSON on stdin, CSV on stdout; docs/external.md)\n";
        return 2;
    }
    try {
        return run(argv[1]);
    } catch (const std::exception& e) {  // bad JSON, unknown engine, failed run: the harness shows this line
        std::cerr << "bouncecheck-external-engine: " << e.what() << '\n';
        return 1;
    }
}
