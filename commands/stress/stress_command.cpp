// `bouncecheck stress`: the stress suite on every selected simulator, its
// invariants judged, the matrix and files written.
#include "commands/command.h"

#include "commands/stress/stress_pipeline.h"
#include "commands/stress/stress_suite.h"
#include "registry/registry.h"
#include "reports/provenance.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <iterator>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

struct StressOptions {
    std::string engines;
    int jobs = 0;  // 0: every core
    std::string out_dir = "bouncecheck-out";
    std::vector<std::string> only;  // rows or scenario names
    double budget = kDefaultBudgetSeconds;
    MonteCarloSet monte_carlo;
    ExternalOptions external;
};

// Exit status of stress (README): 0 every invariant held; 1 an invariant
// broke, a finding about a simulator; 3 a simulator threw or gave up, so the
// matrix has a hole (over 1: the run is incomplete), or one hung and was
// killed; 2 bad input.
int command_stress(const StressOptions& opt) {
    // A program silent for longer than a run's whole budget has hung: it is
    // killed then, not after the default ten minutes.
    ExternalOptions external = opt.external;
    external.timeout_seconds = std::min(external.timeout_seconds, opt.budget);
    const auto extra = ExtraSimulators::from_options(external);
    if (!extra) return kBadInput;
    auto scenarios = load_all(scenario_files(bundled_scenario_dir() / "stress"), extra->command_line_names());
    if (!scenarios) return kBadInput;
    std::vector<StressCase> cases = stress_suite(*scenarios, opt.monte_carlo);
    if (!opt.only.empty()) {
        std::vector<StressCase> chosen;
        for (const auto& name : opt.only) {
            const auto matches = [&](const StressCase& c) { return c.row == name || c.scenario.name == name; };
            if (std::none_of(cases.begin(), cases.end(), matches)) {
                std::set<std::string> rows;
                for (const auto& c : cases) rows.insert(c.row);
                fmt::print(stderr, "error: --only: no stress scenario or row '{}' (rows: {})\n", name,
                           fmt::join(rows, ", "));
                return kBadInput;
            }
        }
        std::copy_if(cases.begin(), cases.end(), std::back_inserter(chosen), [&](const StressCase& c) {
            return std::any_of(opt.only.begin(), opt.only.end(),
                               [&](const std::string& n) { return c.row == n || c.scenario.name == n; });
        });
        cases = std::move(chosen);
    }
    const auto all = built_simulators();
    const auto selected = select_simulators(all, opt.engines);
    if (!selected) return kBadInput;
    const fs::path out_dir = opt.out_dir;
    if (!create_out_dir(out_dir)) return kBadInput;

    StressRequest request;
    request.simulators = extra->with_command_line(*selected);
    request.jobs = opt.jobs;
    request.budget_seconds = opt.budget;
    request.on_progress = [](const StressResult& r, std::size_t done, std::size_t total) {
        const bool lost = r.outcome == StressOutcome::crashed || r.outcome == StressOutcome::hung;
        if (r.row == r.scenario || lost)
            fmt::print(stderr, "[{}/{}] {} {}: {}{}{}\n", done, total, r.scenario, r.simulator, to_string(r.outcome),
                       r.reason.empty() ? "" : ": ", r.reason);
    };
    StressReport report = run_stress(cases, request);
    report.monte_carlo = opt.monte_carlo;
    nlohmann::json engines = nlohmann::json::array();
    nlohmann::json origins = nlohmann::json::object();  // simulators from outside this build
    for (const Simulator* sim : request.simulators) {
        engines.push_back(std::string(sim->name()));
        if (!sim->origin().empty()) origins[std::string(sim->name())] = std::string(sim->origin());
    }
    const nlohmann::json parameters{{"engines", engines},
                                    {"origins", origins},
                                    {"jobs", opt.jobs > 0 ? opt.jobs : 0},
                                    {"only", opt.only},
                                    {"budget_seconds", opt.budget},
                                    {"out", out_dir.string()}};
    fmt::print("{}{}", format_stress_matrix(report), format_stress_failures(report));
    write_stress(report, cases, parameters, out_dir, to_json(this_provenance(/*with_machine=*/true)));
    fmt::print("\nwrote stress.json and stress.csv in {}\n", out_dir.string());
    const auto any = [&](StressOutcome o) {
        return std::any_of(report.results.begin(), report.results.end(),
                           [&](const StressResult& r) { return r.outcome == o; });
    };
    if (any(StressOutcome::crashed) || any(StressOutcome::hung)) return kSimulatorFailed;
    return any(StressOutcome::fail) ? kThresholdExceeded : kOk;
}

}  // namespace

Command add_stress_command(CLI::App& app) {
    auto opt = std::make_shared<StressOptions>();
    CLI::App* command = app.add_subcommand(
        "stress", "Run the stress suite (scenarios/stress/*.toml, wall starts, a Monte-Carlo set) on every selected "
                   "simulator and check its invariants");
    command->add_option("--engines", opt->engines, "Comma-separated simulators (default: every one built)");
    command->add_option("--jobs", opt->jobs, "Runs at once, each in a worker process (default: every core)")
        ->check(CLI::Range(1, 4096));
    command->add_option("--out", opt->out_dir, "Output folder for stress.json and stress.csv")
        ->capture_default_str();
    command->add_option("--only", opt->only,
                        "Only these rows (a scenario's name, monte-carlo, wall-starts) or generated scenarios")
        ->expected(1, -1);
    command->add_option("--budget", opt->budget,
                        "Wall-time budget of one run (s); a run without a result after 1.5 x budget + 1 s is killed "
                        "and reported hung")
        ->capture_default_str()
        ->check(CLI::Range(0.001, 86400.0));
    command->add_option("--monte-carlo", opt->monte_carlo.count,
                        "Size of the generated Monte-Carlo set; scenario n depends only on the seed and n")
        ->capture_default_str()
        ->check(CLI::Range(0, 10'000'000));
    command->add_option("--seed", opt->monte_carlo.seed, "Seed of the Monte-Carlo set")->capture_default_str();
    add_external_options(*command, opt->external);
    return {command, [opt] { return command_stress(*opt); }};
}

}  // namespace bouncecheck
