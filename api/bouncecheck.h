// bouncecheck's C++ API (docs/library.md), installed as <bouncecheck/bouncecheck.h>.
//
// A program loads a scenario, runs its own Simulator beside `reference` and
// `exact`, and gets the comparison and verdicts `bouncecheck run` makes, as
// figures (check_law) or as the same report files (run_and_report). The
// simulator interface it implements is simulators/simulator.h: stream each
// state on the document's clock (simulators/document_clock.h) into the
// RunSink, with the walls touched in the step that made it.
//
// Versioning: within a major version, calls and fields are only added.
#pragma once

#define BOUNCECHECK_API_VERSION_MAJOR 1
#define BOUNCECHECK_API_VERSION_MINOR 0

#include "scenarios/loader.h"            // Scenario, load_scenario, parse_scenario, ScenarioError
#include "simulators/document_clock.h"  // DocumentClock: the document's sample times
#include "simulators/simulator.h"       // Simulator, RunSink, RunOutcome, State, ContactMask
#include "simulators/stream_contacts.h" // StreamContactDetector: contacts from a stream of states

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace bouncecheck {

// How close to the law a simulator must come. The defaults are the bar the
// compiled engines meet in per-contact mode at dt = 1e-3 (docs/engines.md).
struct LawTolerances {
    double first_contact_rel = 0.01;  // first floor contact time, relative to exact's
    int apexes = 3;                   // how many apexes are compared...
    double apex_rel = 0.03;           // ...each within this of exact's height above the floor
    double beyond_wall_abs = 0.002;   // the ball's surface never further beyond a wall than
    double beyond_wall_radius = 0.02; // max(beyond_wall_abs, beyond_wall_radius * radius) (m)
    bool damping_verdict = true;      // and the damping verdict holds (measured alpha and beta,
                                      // the scenario's restitution_abs, tangential_abs, tangential_loss_rel)
};

// One simulator against the law on one scenario.
struct LawCheck {
    bool passed = false;
    std::vector<std::string> failures;  // what did not hold, one line each; empty when passed
    std::string table;                  // the harness's block for the scenario (as `bouncecheck run` prints it)
    // The figures judged (nothing where the run gives none):
    std::optional<double> first_contact_t, exact_first_contact_t;
    std::vector<double> apex_rel;       // per compared apex, |height - exact's| / exact's height above the floor
    double beyond_wall = 0;             // the deepest the ball's surface went beyond a wall (m)
    std::optional<double> alpha_measured, beta_measured;  // means at the impact instant
    std::string damping_verdict;        // "reproduces the damping law", or what differs
};

// Runs `sim` on `s` beside reference and exact (in this process), compares
// it with both as `bouncecheck run` does, and judges it by `t`. A simulator
// that fails, or cannot run `s`, or whose name is a baseline's or not a
// valid name (scenario-name rules), fails the check with its reason. A
// simulator reads the scenario's [engines.NAME] and [thresholds.NAME] of its
// name, as a built engine does.
// An apex at t = 0 (a start at rest vertically) is the start, not a bounce:
// the apexes compared are the first `t.apexes` after it.
LawCheck check_law(const Scenario& s, const Simulator& sim, const LawTolerances& t = {});

// `bouncecheck run` for a program's own simulators: each scenario through
// reference, exact and `simulators` (in this process), the terminal's text
// returned in `terminal` when given, and report.json, report.md, junit.xml,
// bounces.csv and report.html written into `out_dir` (its manifest kept, as
// the command keeps it). Returns the command's exit status: 0 every threshold
// held, 1 one was exceeded, 2 nothing was run (the folder cannot be written,
// or a simulator's name is a baseline's, not a valid name, or given twice;
// the reason in `terminal`), 3 a simulator failed.
int run_and_report(const std::vector<Scenario>& scenarios, const std::vector<const Simulator*>& simulators,
                   const std::filesystem::path& out_dir, std::string* terminal = nullptr);

}  // namespace bouncecheck
