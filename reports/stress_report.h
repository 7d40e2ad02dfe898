// The results of `bouncecheck stress` and their outputs: the terminal matrix
// and failure list, stress.csv, stress.json and the failing generated
// scenarios as files.
#pragma once

#include "platform/output_manifest.h"
#include "scenarios/scenario.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace bouncecheck {

inline constexpr const char* kStressSchema = "bouncecheck-stress/1";
inline constexpr const char* kStressScenarioDir = "stress-scenarios";

// One scenario of the suite and the matrix row it is counted in: a bundled
// file is its own row; a generated family ("monte-carlo", "wall-starts") is one row.
struct StressCase {
    std::string row;
    Scenario scenario;
    bool generated = false;
};

// The generated families' rows; the Monte-Carlo set's default seed and size.
inline constexpr const char* kMonteCarloRow = "monte-carlo";
inline constexpr const char* kWallStartsRow = "wall-starts";
inline constexpr std::uint64_t kMonteCarloSeed = 20260101;
inline constexpr int kMonteCarloCount = 1000;

// Which Monte-Carlo set a suite ran (`stress --monte-carlo COUNT --seed S`).
struct MonteCarloSet {
    std::uint64_t seed = kMonteCarloSeed;
    int count = kMonteCarloCount;
};

enum class Invariant { finite, in_room, energy, time_budget, flat_cost };
inline constexpr Invariant kInvariants[] = {Invariant::finite, Invariant::in_room, Invariant::energy,
                                           Invariant::time_budget, Invariant::flat_cost};
const char* to_string(Invariant i);

// The flat_cost invariant. Subnormal arithmetic costs ~14x (docs/models.md);
// a ball resting in a corner legitimately costs ODE 2.5x a free flight (three
// contact joints in the LCP).
inline constexpr double kCostRatioLimit = 4;
inline constexpr std::int64_t kCostBlockSteps = 256;  // states per timing block
inline constexpr int kCostMinBlocks = 16;             // fewer: too short to judge the cost

struct InvariantCheck {
    Invariant invariant = Invariant::finite;
    bool checked = true;  // false: not judged (e.g. a run too short to time, or cut short)
    bool held = true;
    double tolerance = 0;
    double worst = 0;     // the largest value over the run (StreamRecorder's where it has one)
    std::optional<double> first_t;  // simulated time of the first state beyond the tolerance
    double first_value = 0;         // the value there
};

// crashed: the simulator threw, gave up, or took its process down; hung: no
// result within the watchdog's limit (stress_deadline_seconds), its process killed.
enum class StressOutcome { pass, fail, skipped, crashed, hung };
const char* to_string(StressOutcome o);

struct StressResult {
    std::string row, scenario, simulator;
    StressOutcome outcome = StressOutcome::pass;
    std::string reason;  // skipped, crashed or hung: why; fail: the first invariant broken
    std::vector<InvariantCheck> checks;  // one per kInvariants, in that order
    std::int64_t steps = 0;
    double run_seconds = 0;
    std::string ccd, substeps;  // the settings as the simulator recorded them ("" if none)
    // The check that broke first in simulated time, if any.
    const InvariantCheck* first_broken() const;
};

struct StressReport {
    std::vector<std::string> rows;        // in suite order
    std::vector<std::string> simulators;  // in request order
    std::vector<StressResult> results;    // case-major, simulators in request order
    // results[i] is pair slots[i] of the whole run (case c, simulator e:
    // c x simulators + e). Every pair unless the run was one shard of it.
    std::vector<std::size_t> slots;
    double wall_seconds = 0;
    double budget_seconds = 0;
    MonteCarloSet monte_carlo;
};

// --no-timings: every wall-clock figure (each run's seconds, the flat-cost
// and time-budget checks' values, the whole run's seconds) becomes NaN,
// written as empty or null, so the same input gives the same bytes. The
// checks' verdicts stay: they are judged before.
void leave_out_timings(StressReport& r);

// The terminal matrix: a row per scenario (a family as counts), a column per simulator.
std::string format_stress_matrix(const StressReport& r);
// Every failed, crashed or hung run, one line each, families included.
std::string format_stress_failures(const StressReport& r);
std::string stress_csv(const StressReport& r);
// Writes DIR/stress.json (as nlohmann's dump(2) of the document, a result at
// a time), DIR/stress.csv, and each generated scenario that failed, crashed
// or hung as DIR/stress-scenarios/<name>.toml, each atomically; returns
// what it wrote, relative to DIR.
WrittenFiles write_stress(const StressReport& r, const std::vector<StressCase>& cases, const nlohmann::json& parameters,
                          const std::filesystem::path& out_dir, const nlohmann::json& provenance = nullptr);

}  // namespace bouncecheck
