// `bouncecheck calibrate`: the Coulomb friction coefficient that brings an
// engine closest to a baseline: the reference (the document's Euler, the
// default) or exact (the law's continuous-time solution, "is my engine right?").
//
// No single mu reproduces the document's per-contact factor beta (Coulomb
// friction removes up to mu*(1+e)*|v_n| of tangential speed and spins the
// ball), so mu is chosen to minimise the distance that matters to users:
// the RMS distance between the engine's and the baseline's ball centres at
// the document clock's sample times, over the whole run.
#pragma once

#include "scenarios/scenario.h"
#include "simulators/simulator.h"

#include <filesystem>
#include <string>
#include <vector>

namespace bouncecheck {

enum class CalibrationBaseline { reference, exact };

// "reference" or "exact": the simulator's name.
const char* baseline_name(CalibrationBaseline b);

struct CalibrationResult {
    CalibrationBaseline baseline = CalibrationBaseline::reference;
    double mu = 0;
    double divergence = 0;          // RMS centre distance to the baseline at mu (m)
    double divergence_at_zero = 0;  // the same with mu = 0, for scale
    struct Sample {
        double mu, divergence;
    };
    std::vector<Sample> evaluated;  // every mu tried, in order
};

// Scans mu on a logarithmic grid over [1e-4, mu_max] (and 0), then refines
// around the best grid point by golden-section search. A bounded 1-D search:
// the objective is not smooth in mu (contacts move between steps), so the
// grid guards against a local minimum.
CalibrationResult calibrate_friction(const Scenario& s, const Simulator& engine, double mu_max = 1.0,
                                     CalibrationBaseline baseline = CalibrationBaseline::reference);

// The scenario file's text with `friction = mu` set in [engines.<engine>]
// (the table and key are added if missing), validated before it is returned.
std::string with_calibrated_friction(const std::string& toml_text, const std::string& file_name,
                                     const std::string& engine, const CalibrationResult& result);

}  // namespace bouncecheck
