#include "api/bouncecheck.h"

#include "commands/command.h"
#include "commands/run/run_pipeline.h"
#include "exact/exact_simulator.h"
#include "platform/output_manifest.h"
#include "reference/reference_simulator.h"
#include "reports/run_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <set>
#include <string_view>

namespace bouncecheck {

namespace {

// The baselines every row is compared with, and the caller's rows after them.
struct BaselineSimulators {
    std::unique_ptr<const Simulator> reference = make_reference_simulator();
    std::unique_ptr<const Simulator> exact = make_exact_simulator();
    std::vector<const Simulator*> with(const std::vector<const Simulator*>& own) const {
        std::vector<const Simulator*> all = {reference.get(), exact.get()};
        all.insert(all.end(), own.begin(), own.end());
        return all;
    }
};

// Why a program's simulator cannot stand beside the baselines, or nothing:
// its name names its row and its output files, so it follows the
// scenario-name rules, and is not a baseline's. (A built engine from the
// registry keeps its own name, and with it its [engines.NAME] and
// [thresholds.NAME] tables.)
std::optional<std::string> simulator_name_problem(const Simulator& sim) {
    if (sim.name() == "reference" || sim.name() == "exact")
        return fmt::format("'{}' is a baseline's name: give the simulator its own", sim.name());
    if (auto problem = name_problem(sim.name())) return fmt::format("simulator name '{}': {}", sim.name(), *problem);
    return std::nullopt;
}

// The first contact with the floor, as the comparison counts floor contacts.
std::optional<double> first_floor_contact(const SimulatorSummary& r, const Scenario& s) {
    const std::vector<ContactEvent> floor = floor_contacts(r, s.vertical_axis());
    return floor.empty() ? std::nullopt : std::optional<double>(floor.front().t);
}

// `apexes`: at least this many bounces compared (the scenario's
// bounce_count, default 5, may ask for fewer).
ScenarioRun run_in_process(const Scenario& s, const std::vector<const Simulator*>& simulators, bool plots,
                           int apexes = 0) {
    RunRequest request;
    request.simulators = simulators;
    request.plots = plots;
    request.isolate = false;  // the caller's simulator lives in this process
    if (apexes > s.thresholds.all.bounce_count.value_or(kDefaultBounceCount))
        request.threshold_overrides.bounce_count = apexes;
    return run_scenario(s, request);
}

}  // namespace

LawCheck check_law(const Scenario& s, const Simulator& sim, const LawTolerances& t) {
    LawCheck c;
    const auto fail = [&](std::string why) { c.failures.push_back(std::move(why)); };
    if (auto problem = simulator_name_problem(sim)) {
        fail(*problem);
        return c;
    }
    const BaselineSimulators baselines;
    RunReport report;
    // One bounce more than asked: the first apex may be the start itself.
    report.scenarios.push_back(run_in_process(s, baselines.with({&sim}), /*plots=*/false, t.apexes + 1));
    const ScenarioRun& run = report.scenarios.back();
    c.table = format_run(report, /*colour=*/false);
    const SimulatorSummary &exact = run.results[1], &self = run.results[2];
    if (self.status != RunStatus::ok) {
        fail(fmt::format("{} {}: {}", sim.name(), to_string(self.status), self.reason));
        return c;
    }
    const Comparison& compared = *run.comparisons[2];

    c.exact_first_contact_t = first_floor_contact(exact, s);
    c.first_contact_t = first_floor_contact(self, s);
    if (c.exact_first_contact_t && !c.first_contact_t) {
        fail(fmt::format("first floor contact: none, where exact's is at {:.6g} s", *c.exact_first_contact_t));
    } else if (c.exact_first_contact_t) {
        const double rel = std::abs(*c.first_contact_t - *c.exact_first_contact_t) / *c.exact_first_contact_t;
        if (!(rel <= t.first_contact_rel))
            fail(fmt::format("first floor contact at {:.6g} s, exact's at {:.6g} s: {:.3g}% off (tolerance {:.3g}%)",
                             *c.first_contact_t, *c.exact_first_contact_t, 100 * rel, 100 * t.first_contact_rel));
    }

    // The apexes after the start (an apex at t = 0 is the initial state itself).
    const auto& bounces = compared.vs_exact.bounces;
    std::size_t first = 0;
    if (!bounces.empty() && !exact.apexes.empty() && exact.apexes.front().t == 0) first = 1;
    const std::size_t wanted = static_cast<std::size_t>(std::max(t.apexes, 0));
    const std::size_t exact_apexes = exact.apexes.size() > first ? exact.apexes.size() - first : 0;
    for (std::size_t k = first; k < bounces.size() && c.apex_rel.size() < wanted; ++k) {
        c.apex_rel.push_back(bounces[k].rel_diff);
        if (!(bounces[k].rel_diff <= t.apex_rel))
            fail(fmt::format("apex {} after the start: {:.6g} m, exact's {:.6g} m: {:.3g}% off (tolerance {:.3g}%)",
                             k - first + 1,
                             bounces[k].height, bounces[k].baseline_height, 100 * bounces[k].rel_diff,
                             100 * t.apex_rel));
    }
    if (c.apex_rel.size() < std::min(wanted, exact_apexes))
        fail(fmt::format("apexes: {} compared, where exact has {} of the {} asked for", c.apex_rel.size(),
                         std::min(wanted, exact_apexes), wanted));

    c.beyond_wall = self.max_penetration;
    const double beyond_limit = std::max(t.beyond_wall_abs, t.beyond_wall_radius * s.radius);
    if (!(c.beyond_wall <= beyond_limit))
        fail(fmt::format("beyond a wall: {:.3g} m at the deepest (tolerance {:.3g} m)", c.beyond_wall, beyond_limit));

    const DampingCheck& damping = compared.damping;
    c.damping_verdict = damping.verdict;
    if (damping.contacts > 0) c.alpha_measured = damping.normal_mean;
    if (damping.tangential_contacts > 0) c.beta_measured = damping.tangential_mean;
    if (t.damping_verdict && !damping.reproduces) fail("damping: " + damping.verdict);

    c.passed = c.failures.empty();
    return c;
}

int run_and_report(const std::vector<Scenario>& scenarios, const std::vector<const Simulator*>& simulators,
                   const std::filesystem::path& out_dir, std::string* terminal) {
    const auto refuse = [&](const std::string& why) {
        if (terminal) *terminal = "error: " + why + "\n";
        return kBadInput;
    };
    std::set<std::string_view> names;
    for (const Simulator* sim : simulators) {
        if (auto problem = simulator_name_problem(*sim)) return refuse(*problem);
        if (!names.insert(sim->name()).second) return refuse(fmt::format("two simulators are named '{}'", sim->name()));
    }
    std::string why;
    auto out = OutputFolder::open(out_dir, &why);
    if (!out) return refuse(why);
    const BaselineSimulators baselines;
    RunReport report;
    report.provenance = this_provenance(/*with_machine=*/true);
    for (const Scenario& s : scenarios) report.scenarios.push_back(run_in_process(s, baselines.with(simulators), true));
    RunVerdict verdict = run_verdict(report);
    verdict.exit_status = run_exit_status(verdict);
    const WrittenFiles written = write_reports(report, out_dir, &verdict);
    const std::string removed = format_manifest_update(out->record("run", written), out_dir);
    if (terminal) *terminal = format_run(report, /*colour=*/false) + removed + "\n" + format_verdict(verdict);
    return verdict.exit_status;
}

}  // namespace bouncecheck
