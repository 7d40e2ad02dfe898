// What was run where (issue: baselines): the build that made a report (its
// version, git commit, compiler and flags, every engine library and its
// Debian package) and the machine and moment it ran on (CPU, cores, date,
// command line). Every report.json, sweep.json and stress.json carries it;
// `bouncecheck diff` shows it for both sides.
//
// The build block is a function of the build alone. The machine block is
// left out under --no-timings, so that output stays a function of the input
// (and the build) alone.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace bouncecheck {

struct Provenance {
    struct Engine {
        std::string simulator, library, package;  // package: "libbullet-dev 3.24+dfsg-2", or empty if unknown
    };
    struct Build {
        std::string version;      // bouncecheck's
        std::string git_commit;   // when built; empty if not built from a git checkout
        bool git_dirty = false;   // uncommitted changes when built
        std::string compiler;     // "GNU 12.2.0"
        std::string build_type;   // "Release"
        std::string flags;        // the C++ flags of that build type
        std::vector<Engine> engines;
    } build;
    struct Machine {
        std::string cpu;  // the CPU model, from /proc/cpuinfo
        unsigned cores = 0;
        std::string date;  // UTC, ISO 8601
        std::string command_line;
    };
    std::optional<Machine> machine;
};

// This build's block; `machine` too unless `with_machine` is false (--no-timings).
Provenance this_provenance(bool with_machine);

// The command line main() was given, for the machine block.
void set_command_line(int argc, const char* const* argv);

nlohmann::json to_json(const Provenance& p);
// One line: "bouncecheck 0.1.0 (git 07724a8, GNU 12.2.0, Release) on AMD EPYC (2 cores), 2026-11-27T21:50:00Z".
std::string format_provenance(const Provenance& p);
// The same line from a report's "provenance" object (any report, any age):
// "unknown (the report has no provenance)" when absent.
std::string format_provenance(const nlohmann::json& provenance);

}  // namespace bouncecheck
