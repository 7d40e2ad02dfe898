// `bouncecheck calibrate`: the friction coefficient that brings an engine
// closest to the reference, optionally written into the scenario file.
#include "commands/command.h"

#include "commands/calibrate/calibrate_pipeline.h"
#include "platform/atomic_file.h"
#include "platform/did_you_mean.h"
#include "registry/registry.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace bouncecheck {

namespace {

struct CalibrateOptions {
    std::string file;
    std::vector<std::string> engines;  // exactly one: the list option every command shares
    std::string engine;
    double max_mu = 1.0;
    std::string against = "reference";
    bool write = false;
};

int command_calibrate(CalibrateOptions opt) {
    std::erase(opt.engines, std::string());
    if (opt.engines.size() != 1) {
        fmt::print(stderr, "error: --engines: calibrate tunes one engine at a time ({} given)\n", opt.engines.size());
        return kBadInput;
    }
    opt.engine = opt.engines.front();
    auto scenarios = load_all({opt.file});
    if (!scenarios) return kBadInput;
    const Scenario& s = scenarios->front();
    auto all = built_simulators();
    const auto it = std::find_if(all.begin(), all.end(), [&](const auto& sim) { return sim->name() == opt.engine; });
    if (it == all.end() || opt.engine == "reference" || opt.engine == "exact") {
        std::vector<std::string> engines;
        for (const auto& sim : all)
            if (sim->name() != "reference" && sim->name() != "exact") engines.push_back(std::string(sim->name()));
        fmt::print(stderr, "error: --engines: '{}' is not a built engine{} (built: {})\n", opt.engine,
                   did_you_mean(opt.engine, engines), fmt::join(engines, ", "));
        return kBadInput;
    }
    if (s.engine_options(opt.engine).tangential_model != TangentialModel::friction) {
        fmt::print(stderr, "error: {}: [engines.{}] uses tangential_model = \"per-contact\"; calibration tunes friction\n",
                   opt.file, opt.engine);
        return kBadInput;
    }
    // Asked at the largest mu the search tries: an engine may run a scenario
    // frictionless but refuse Coulomb friction (siconos-ed).
    Scenario with_friction = s;
    with_friction.engines[opt.engine].friction = opt.max_mu;
    if (auto why = (*it)->cannot_run(with_friction)) {
        fmt::print(stderr, "error: {}: {}\n", opt.file, *why);
        return kBadInput;
    }
    const CalibrationResult r = calibrate_friction(
        s, **it, opt.max_mu, opt.against == "exact" ? CalibrationBaseline::exact : CalibrationBaseline::reference);
    fmt::print("{} on {}: objective = RMS distance of the ball centre from {} over the run\n", opt.engine, s.name,
               baseline_name(r.baseline));
    fmt::print("  mu = {:.6g}: divergence {:.4g} m (mu = 0: {:.4g} m; {} runs)\n", r.mu, r.divergence,
               r.divergence_at_zero, r.evaluated.size());
    if (opt.write) {
        std::ifstream in(opt.file, std::ios::binary);
        std::stringstream text;
        text << in.rdbuf();
        write_file_atomically(opt.file, with_calibrated_friction(text.str(), opt.file, opt.engine, r));
        fmt::print("  wrote friction = {:.6g} into [engines.{}] of {}\n", r.mu, opt.engine, opt.file);
    }
    return kOk;
}

}  // namespace

Command add_calibrate_command(CLI::App& app) {
    auto opt = std::make_shared<CalibrateOptions>();
    CLI::App* command = app.add_subcommand(
        "calibrate", "Find the friction coefficient mu that brings an engine closest to the reference");
    command->add_option("scenario", opt->file, "Scenario file")->required();
    add_list_option(*command, "--engines,--engine", opt->engines, "The engine to calibrate (one)")->required();
    command->add_option("--max-mu", opt->max_mu, "Upper end of the search")
        ->capture_default_str()
        ->check(finite_between(1e-3, 10.0));
    command
        ->add_option("--against", opt->against,
                     "Baseline to come closest to: reference (the document's Euler) or exact (the law's solution)")
        ->check(CLI::IsMember({"reference", "exact"}))
        ->capture_default_str();
    command->add_flag("--write", opt->write, "Write the value into the file's [engines.<engine>] table");
    set_exit_status_help(*command, {{kOk, "calibrated (and with --write, written)"},
                                   {kBadInput, "bad input or usage: nothing was run"}});
    return {command, [opt] { return command_calibrate(*opt); }};
}

}  // namespace bouncecheck
