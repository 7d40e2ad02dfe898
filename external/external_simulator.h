// Simulators bouncecheck did not build (docs/external.md): any program that
// speaks the external protocol, and a recorded trajectory file. Both stream
// their states through the same reader and contact detector, so every
// metric, comparison and report treats them as it treats an engine.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/simulator.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace bouncecheck {

inline constexpr int kExternalProtocol = 1;
inline constexpr double kDefaultExternalTimeoutSeconds = 600;
// Where a command sets no budget of its own (`run` and `sweep` without
// --budget), an external program may still run at most this long in all.
inline constexpr double kDefaultExternalTotalSeconds = 3600;

// How long an external program may run: killed after `silence_seconds`
// without output (--external-timeout), or after `total_seconds` in all (the
// command's --budget, or the default above), whichever comes first.
struct ExternalLimits {
    double silence_seconds = kDefaultExternalTimeoutSeconds;
    double total_seconds = kDefaultExternalTotalSeconds;
};

// NAME=COMMAND, from --external or a scenario's [external.NAME].
struct ExternalDeclaration {
    ExternalDeclaration() = default;
    ExternalDeclaration(std::string name_, std::vector<std::string> command_)
        : name(std::move(name_)), command(std::move(command_)) {}

    std::string name;
    std::vector<std::string> command;  // argv; the program as resolve_program gives it
    // The program answers scenario after scenario in one process
    // (docs/external.md, Sessions): it is started once per worker process
    // and working folder, and kept while its replies are whole.
    bool session = false;
    // A built-in engine hosted by the program (the Node engines): the
    // scenario's [engines.NAME] shared options are the harness's, and reach
    // the program normalized, with the engine's own keys beside them.
    bool builtin_engine = false;
    std::string origin;  // the rows' `source`; empty: "external: COMMAND"
};

// Runs `declaration`'s program once per scenario, in the scenario's folder,
// within `limits`.
std::unique_ptr<const Simulator> make_external_simulator(ExternalDeclaration declaration, ExternalLimits limits);

// Replays the trajectory in `file` (checked beforehand with check_trajectory_file).
std::unique_ptr<const Simulator> make_imported_trajectory(std::string name, std::string file);

// The JSON object an external program reads on its standard input, on one
// line. `builtin_engine`: see ExternalDeclaration.
std::string external_input(const Scenario& s, const std::string& name, const std::string& settings_file,
                           bool builtin_engine = false);

// An external's settings file is a short JSON array of flat objects: at most
// 1 MiB (so a value cannot balloon every report) and 8 levels deep.
inline constexpr std::size_t kMaxExternalSettingsBytes = 1u << 20;
inline constexpr int kMaxExternalSettingsDepth = 8;

// The settings an external program wrote (a JSON array of {key, value, why});
// throws std::runtime_error saying what is wrong with it.
std::vector<Setting> parse_external_settings(const std::string& text);

}  // namespace bouncecheck
