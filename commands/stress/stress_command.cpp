// `bouncecheck stress`: the stress suite on every selected simulator, its
// invariants judged, the matrix and files written.
#include "commands/command.h"
#include "platform/printable_text.h"

#include "commands/shards.h"
#include "commands/stress/stress_pipeline.h"
#include "commands/stress/stress_suite.h"
#include "platform/did_you_mean.h"
#include "registry/registry.h"
#include "reports/provenance.h"
#include "scenarios/scenario_toml.h"
#include "reports/json_number.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

struct StressOptions {
    std::vector<std::string> engines;
    bool no_timings = false;  // an output choice: not in the shard's options
    int jobs = 0;  // 0: every core
    std::string out_dir = "bouncecheck-out";
    std::vector<std::string> only;  // rows or scenario names
    double budget = kDefaultBudgetSeconds;
    MonteCarloSet monte_carlo;
    ExternalOptions external;
    std::string shard;  // K/N, or empty: the whole run
};

// What a shard hands merge to plan the same run (all but --out and --shard).
nlohmann::json to_json(const StressOptions& o) {
    return {{"engines", o.engines},
            {"jobs", o.jobs},
            {"only", o.only},
            {"budget", o.budget},
            {"monte_carlo", {{"seed", o.monte_carlo.seed}, {"count", o.monte_carlo.count}}},
            {"external", to_json(o.external)}};
}

StressOptions stress_options_from(const nlohmann::json& j) {
    StressOptions o;
    o.engines = j.at("engines").get<std::vector<std::string>>();
    o.jobs = j.at("jobs").get<int>();
    o.only = j.at("only").get<std::vector<std::string>>();
    o.budget = j.at("budget").get<double>();
    o.monte_carlo = {j.at("monte_carlo").at("seed").get<std::uint64_t>(), j.at("monte_carlo").at("count").get<int>()};
    o.external = external_options_from(j.at("external"));
    return o;
}

// The run the options describe: its cases and simulators, before anything runs.
struct StressPlan {
    ExtraSimulators extra;
    std::vector<std::unique_ptr<const Simulator>> built;
    std::vector<StressCase> cases;
    std::vector<const Simulator*> simulators;

    // stress.json's "parameters".
    nlohmann::json parameters(const StressOptions& opt, const fs::path& out_dir) const {
        return {{"engines", simulator_names(simulators)},
                {"origins", simulator_origins(simulators)},
                {"jobs", opt.jobs > 0 ? opt.jobs : 0},
                {"only", opt.only},
                {"budget_seconds", opt.budget},
                {"out", out_dir.string()}};
    }
    // Everything that decides the run's results: shards and merge compare it.
    // The generated scenarios are the build's and the options' (the seed):
    // only the files' scenarios are read from outside.
    std::string fingerprint(const StressOptions& opt) const {
        nlohmann::json options = to_json(opt);
        options.erase("jobs");
        std::string inputs = fmt::format("{}\n{}\n{} cases\n", json_text(options), json_text(parameters(opt, {})), cases.size());
        for (const StressCase& c : cases)
            if (!c.generated) inputs += c.row + "\n" + scenario_toml(c.scenario);
        return run_fingerprint("stress", inputs);
    }
};

std::optional<StressPlan> plan_stress(const StressOptions& opt) {
    // A program silent for longer than a run's whole budget has hung: it is
    // killed then, not after the default ten minutes; and one still talking
    // at the budget's end is killed there too.
    ExternalOptions external = opt.external;
    external.timeout_seconds = std::min(external.timeout_seconds, opt.budget);
    external.total_seconds = opt.budget;
    auto extra = ExtraSimulators::from_options(external);
    if (!extra) return std::nullopt;
    auto scenarios = load_all(scenario_files(bundled_scenario_dir() / "stress"), extra->command_line_names());
    if (!scenarios) return std::nullopt;
    std::vector<std::string> only = opt.only;
    std::erase(only, std::string());  // "a,,b": the list's empty items
    // Only the named cases are made: a million generated scenarios with
    // --only picking one cost that one's memory, not a million's.
    std::set<std::string> matched;
    StressCaseFilter keep;
    if (!only.empty()) {
        keep = [&](const std::string& row, const std::string& name) {
            bool any = false;
            for (const std::string& n : only) {
                if (n != row && n != name) continue;
                matched.insert(n);
                any = true;
            }
            return any;
        };
    }
    std::vector<StressCase> cases = stress_suite(*scenarios, opt.monte_carlo, keep);
    for (const auto& name : only) {
        if (matched.count(name)) continue;
        std::set<std::string> rows;
        std::vector<std::string> names;
        for (const Scenario& s : *scenarios) rows.insert(s.name);
        rows.insert(kWallStartsRow);
        for (const Scenario& s : wall_start_scenarios()) names.push_back(s.name);
        if (opt.monte_carlo.count > 0) {
            rows.insert(kMonteCarloRow);
            names.push_back(fmt::format("{}-0000", kMonteCarloRow));
        }
        names.insert(names.end(), rows.begin(), rows.end());
        const std::string generated =
            opt.monte_carlo.count > 0
                ? fmt::format("; generated: {}-0000 to {}-{:04d}", kMonteCarloRow, kMonteCarloRow, opt.monte_carlo.count - 1)
                : "";
        fmt::print(stderr, "error: --only: no stress scenario or row '{}'{} (rows: {}{})\n", name,
                   did_you_mean(name, names), fmt::join(rows, ", "), generated);
        return std::nullopt;
    }
    StressPlan plan{std::move(*extra), built_simulators(external.limits()), std::move(cases), {}};
    const auto selected = select_simulators(plan.built, opt.engines);
    if (!selected) return std::nullopt;
    plan.simulators = plan.extra.with_command_line(*selected);
    return plan;
}

// Exit status of stress (docs/stress.md): 0 every invariant held; 1 an invariant
// broke, a finding about a simulator; 3 a simulator threw or gave up, so the
// matrix has a hole (over 1: the run is incomplete), or one hung and was
// killed; 2 bad input.
int stress_exit_status(const StressReport& report) {
    const auto any = [&](StressOutcome o) {
        return std::any_of(report.results.begin(), report.results.end(),
                           [&](const StressResult& r) { return r.outcome == o; });
    };
    if (any(StressOutcome::crashed) || any(StressOutcome::hung)) return kSimulatorFailed;
    return any(StressOutcome::fail) ? kThresholdExceeded : kOk;
}

// The matrix on the terminal, and stress.json, stress.csv and the failing generated scenarios in `out_dir`.
// `written`: what the command wrote before (a shard's file).
int report_stress(StressReport report, const std::vector<StressCase>& cases, const StressOptions& opt,
                  OutputFolder& out, nlohmann::json parameters, WrittenFiles written = {}) {
    report.monte_carlo = opt.monte_carlo;
    if (opt.no_timings) leave_out_timings(report);
    fmt::print("{}{}", format_stress_matrix(report), format_stress_failures(report));
    for (std::string& file : write_stress(report, cases, parameters, out.dir(),
                                          to_json(this_provenance(/*with_machine=*/!opt.no_timings))))
        written.push_back(std::move(file));
    fmt::print("\nwrote stress.json and stress.csv in {}\n", out.dir().string());
    record_outputs(out, "stress", written);
    return stress_exit_status(report);
}

int command_stress(const StressOptions& opt) {
    const auto plan = plan_stress(opt);
    if (!plan) return kBadInput;
    const fs::path out_dir = opt.out_dir;
    auto out = OutputFolder::open(out_dir);
    if (!out) return kBadInput;

    StressRequest request;
    request.simulators = plan->simulators;
    request.jobs = opt.jobs;
    request.budget_seconds = opt.budget;
    request.shard = shard_of(opt.shard);
    request.on_progress = [](const StressResult& r, std::size_t done, std::size_t total) {
        const bool lost = r.outcome == StressOutcome::crashed || r.outcome == StressOutcome::hung;
        if (r.row == r.scenario || lost)
            fmt::print(stderr, "[{}/{}] {} {}: {}{}{}\n", done, total, r.scenario, r.simulator, to_string(r.outcome),
                       r.reason.empty() ? "" : ": ", r.reason);
    };
    StressReport report = run_stress(plan->cases, request);
    nlohmann::json parameters = plan->parameters(opt, out_dir);
    if (request.shard.whole()) return report_stress(std::move(report), plan->cases, opt, *out, std::move(parameters));

    // The shard's own results and scenarios as files, and what merge needs to put them back.
    parameters["shard"] = opt.shard;
    ShardFile file{"stress", request.shard, plan->cases.size() * plan->simulators.size(), plan->fingerprint(opt),
                   to_json(opt), report.wall_seconds, report.slots, {}};
    for (const StressResult& r : report.results) file.results.push_back(encode_stress_result(r));
    WrittenFiles written = write_shard_file(out_dir, file);
    std::vector<StressCase> own;  // each case the shard ran a pair of, once (slots ascend, case-major)
    std::size_t last = plan->cases.size();
    for (std::size_t slot : report.slots) {
        const std::size_t c = slot / plan->simulators.size();
        if (c != last) own.push_back(plan->cases[c]);
        last = c;
    }
    return report_stress(std::move(report), own, opt, *out, std::move(parameters), std::move(written));
}

}  // namespace

int merge_stress(const ShardSet& shards, OutputFolder& out, bool no_timings) {
    StressOptions opt;
    try {
        opt = stress_options_from(shards.options);
        opt.no_timings = no_timings;
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: the shards' stress options are unreadable: {}\n", error_text(e));
        return kBadInput;
    }
    const auto plan = plan_stress(opt);
    if (!plan) return kBadInput;
    if (!shards_ran_this_plan(shards, plan->fingerprint(opt))) return kBadInput;
    StressReport report;
    try {
        report = stress_report_from_results(plan->cases, simulator_names(plan->simulators), opt.budget, shards.results);
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: a shard's result is unreadable: {}\n", error_text(e));
        return kBadInput;
    }
    report.wall_seconds = shards.wall_seconds;
    return report_stress(std::move(report), plan->cases, opt, out, plan->parameters(opt, out.dir()));
}

Command add_stress_command(CLI::App& app) {
    auto opt = std::make_shared<StressOptions>();
    CLI::App* command = app.add_subcommand(
        "stress", "Run the stress suite (scenarios/stress/*.toml, wall starts, a Monte-Carlo set) on every selected "
                   "simulator and check its invariants");
    add_list_option(*command, "--engines", opt->engines, "Simulators (default: every one built)");
    command->add_option("--jobs", opt->jobs, "Runs at once, each in a worker process (default: every core)")
        ->check(CLI::Range(1, 4096));
    command->add_option("--out", opt->out_dir, "Output folder for stress.json and stress.csv")
        ->capture_default_str();
    add_no_timings_flag(*command, opt->no_timings);
    add_list_option(*command, "--only", opt->only,
                    "Only these rows (a scenario's name, monte-carlo, wall-starts) or generated scenarios")
        ->expected(1, -1)
        ->allow_extra_args(true);  // space-separated too, as before lists took commas: stress has no positionals
    command->add_option("--budget", opt->budget,
                        "Wall-time budget of one run (s); a run without a result after 1.5 x budget + 1 s is killed "
                        "and reported hung")
        ->capture_default_str()
        ->check(finite_between(0.001, 86400.0));
    command->add_option("--monte-carlo", opt->monte_carlo.count,
                        "Size of the generated Monte-Carlo set; scenario n depends only on the seed and n")
        ->capture_default_str()
        ->check(CLI::Range(0, 10'000'000));
    command->add_option("--seed", opt->monte_carlo.seed, "Seed of the Monte-Carlo set")
        ->capture_default_str()
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                // CLI11 clamps -1, 2^64 and 1e23 to 2^64 - 1 without a word: digits only, within 64 bits.
                std::uint64_t seed = 0;
                const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), seed);
                if (text.empty() || ec != std::errc() || end != text.data() + text.size())
                    return fmt::format("'{}' is not a whole number from 0 to {}", text.substr(0, 40),
                                       std::numeric_limits<std::uint64_t>::max());
                return {};
            },
            "UINT64"));
    add_shard_option(*command, opt->shard);
    add_external_options(*command, opt->external);
    set_exit_status_help(*command, {{kOk, "every invariant held"},
                                   {kThresholdExceeded, "an invariant broke: the simulator, scenario and invariant are named"},
                                   {kBadInput, "bad input or usage: nothing was run"},
                                   {kSimulatorFailed, "a simulator crashed, gave up or hung (wins over 1)"}});
    return {command, [opt] { return command_stress(*opt); }};
}

}  // namespace bouncecheck
