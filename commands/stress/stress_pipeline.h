// `bouncecheck stress`: every simulator on scenarios built to break it (fast
// balls, large steps, extreme sizes, elastic and dead bounces, corners, wall
// starts, no gravity, diagonal gravity, a long horizon, a Monte-Carlo set),
// each run watched for invariants that a sound simulator keeps whatever the
// scenario: a finite state, the ball in the room, no energy gained, a run that
// ends in bounded time, and a cost per step that stays flat.
#pragma once

#include "simulators/simulator.h"
#include "scenarios/scenario.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <random>
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

inline constexpr const char* kMonteCarloRow = "monte-carlo";
inline constexpr const char* kWallStartsRow = "wall-starts";
inline constexpr std::uint64_t kMonteCarloSeed = 20260101;
inline constexpr int kMonteCarloCount = 1000;

// Uniform double in [0, 1) from the top 53 bits of one draw. The suite's
// random numbers use only this and integer arithmetic on the engine's output,
// whose sequence the C++ standard fixes, so every build generates the same set.
double unit_draw(std::mt19937_64& g);

// `count` random valid scenarios (they pass the loader's validation) from
// `seed`: 2D or 3D, room sides 0.2-3 m, radius 0.5-20% of the smallest side,
// speeds up to 2 m/s per axis, gravity up to 10 m/s^2 (sometimes none,
// sometimes tilted), alpha and beta over [0, 1] with 0 and 1 themselves
// frequent, starts touching walls, dt from 2.4e-4 to 0.0625 s, 200-2000 steps.
std::vector<Scenario> monte_carlo_scenarios(std::uint64_t seed, int count);

// A ball starting in contact with each wall of a 2D and a 3D room, moving
// into it, away from it, and at rest: 30 scenarios.
std::vector<Scenario> wall_start_scenarios();

// The whole suite: the given files' scenarios (one row each), then the
// wall-start and Monte-Carlo families.
std::vector<StressCase> stress_suite(const std::vector<Scenario>& files);

// Scenario text that load_scenario reads back to the same scenario (numbers
// with 17 significant digits; engine tables and thresholds left out).
std::string scenario_toml(const Scenario& s);

enum class Invariant { finite, in_room, energy, time_budget, flat_cost };
inline constexpr Invariant kInvariants[] = {Invariant::finite, Invariant::in_room, Invariant::energy,
                                           Invariant::time_budget, Invariant::flat_cost};
const char* to_string(Invariant i);

// The tolerance of each invariant for one scenario (see stress_limits).
struct StressLimits {
    double penetration = 0;        // m the ball's surface may reach beyond a wall
    double energy_rise = 0;        // J/kg the energy may rise above its initial value
    double budget_seconds = 0;     // wall time of one run
    double cost_ratio = 0;         // late over early ns/step
};
// Penetration: half the radius (beyond r the centre has left the room).
// Energy (alpha, beta <= 1): 1% of the energy the ball can give up at the
// start (kinetic, plus potential down to the walls gravity points at), plus
// k^2 |g|^2 dt^2, the energy of the micro-bounce a stepped simulator keeps at
// rest (k as in StreamRecorder's rest detection). Cost: late ns/step at most
// kCostRatioLimit times early ns/step.
StressLimits stress_limits(const Scenario& s, double budget_seconds);

inline constexpr double kDefaultBudgetSeconds = 30;
// Subnormal arithmetic costs ~14x (docs/models.md); a ball resting in a corner
// legitimately costs ODE 2.5x a free flight (three contact joints in the LCP).
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

enum class StressOutcome { pass, fail, skipped, crashed };
const char* to_string(StressOutcome o);

struct StressResult {
    std::string row, scenario, simulator;
    StressOutcome outcome = StressOutcome::pass;
    std::string reason;  // skipped or crashed: why; fail: the first invariant broken
    std::vector<InvariantCheck> checks;  // one per kInvariants, in that order
    std::int64_t steps = 0;
    double run_seconds = 0;
    std::string ccd, substeps;  // the settings as the simulator recorded them ("" if none)
    // The check that broke first in simulated time, if any.
    const InvariantCheck* first_broken() const;
};

struct StressRequest {
    std::vector<const Simulator*> simulators;
    int jobs = 0;  // worker threads; 0: every core
    double budget_seconds = kDefaultBudgetSeconds;
    // Called (under a lock, from a worker thread) as each run finishes.
    std::function<void(const StressResult&, std::size_t done, std::size_t total)> on_progress;
};

struct StressReport {
    std::vector<std::string> rows;        // in suite order
    std::vector<std::string> simulators;  // in request order
    std::vector<StressResult> results;    // case-major, simulators in request order
    double wall_seconds = 0;
    double budget_seconds = 0;
};

// Runs `s` on `sim` and judges every invariant.
StressResult run_stress_case(const StressCase& c, const Simulator& sim, double budget_seconds);

// Every (case, simulator) pair, in parallel over pairs (oneTBB), the engines
// with shared library state one run at a time (serial_engine_reason).
StressReport run_stress(const std::vector<StressCase>& cases, const StressRequest& request);

// The terminal matrix: a row per scenario (a family as counts), a column per simulator.
std::string format_stress_matrix(const StressReport& r);
// Every failed or crashed run, one line each, families included.
std::string format_stress_failures(const StressReport& r);
std::string stress_csv(const StressReport& r);
nlohmann::json stress_json(const StressReport& r, const std::vector<StressCase>& cases,
                           const nlohmann::json& parameters);
// Writes DIR/stress.json and DIR/stress.csv, and each generated scenario that
// failed or crashed as DIR/stress-scenarios/<name>.toml, each atomically.
void write_stress(const StressReport& r, const std::vector<StressCase>& cases, const nlohmann::json& parameters,
                  const std::filesystem::path& out_dir);

}  // namespace bouncecheck
