#include "commands/calibrate/calibrate_pipeline.h"

#include "exact/exact_simulator.h"
#include "metrics/summary.h"
#include "reference/reference_simulator.h"
#include "scenarios/loader.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace bouncecheck {

namespace {

// RMS distance between the two runs' centres, sample by sample (both follow
// the document clock, so sample n of one is at the time of sample n of the other).
double rms_distance(const std::vector<State>& a, const std::vector<State>& b) {
    const std::size_t n = std::min(a.size(), b.size());
    if (n == 0) return std::numeric_limits<double>::infinity();
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) sum += (a[i].p - b[i].p).squaredNorm();
    return std::sqrt(sum / static_cast<double>(n));
}

class Objective {
public:
    Objective(const Scenario& s, const Simulator& engine, CalibrationResult& out)
        : scenario_(s), engine_(engine), out_(out) {
        const auto baseline = out.baseline == CalibrationBaseline::exact ? make_exact_simulator()
                                                                          : make_reference_simulator();
        StateVector states;
        record_run(*baseline, s, &states);
        baseline_ = std::move(states.states);
    }

    double operator()(double mu) {
        Scenario s = scenario_;
        EngineOptions& options = s.engines[std::string(engine_.name())];
        options.tangential_model = TangentialModel::friction;
        options.tangential_unset = false;
        options.friction = mu;
        StateVector states;
        const SimulatorSummary summary = record_run(engine_, s, &states);
        const double d = summary.status == RunStatus::ok ? rms_distance(states.states, baseline_)
                                                         : std::numeric_limits<double>::infinity();
        out_.evaluated.push_back({mu, d});
        return d;
    }

private:
    const Scenario& scenario_;
    const Simulator& engine_;
    CalibrationResult& out_;
    std::vector<State> baseline_;  // its states on the document clock
};

}  // namespace

const char* baseline_name(CalibrationBaseline b) {
    return b == CalibrationBaseline::exact ? "exact" : "reference";
}

CalibrationResult calibrate_friction(const Scenario& s, const Simulator& engine, double mu_max,
                                     CalibrationBaseline baseline) {
    if (auto why = engine.cannot_run(s)) throw std::runtime_error(*why);
    CalibrationResult result;
    result.baseline = baseline;
    Objective objective(s, engine, result);

    // Grid: 0, then 4 points per decade from 1e-4 to mu_max.
    std::vector<double> grid{0.0};
    for (double mu = 1e-4; mu < mu_max * (1 + 1e-9); mu *= std::pow(10.0, 0.25)) grid.push_back(mu);
    if (grid.back() < mu_max) grid.push_back(mu_max);
    std::vector<double> values;
    for (double mu : grid) values.push_back(objective(mu));
    result.divergence_at_zero = values.front();
    std::size_t best = 0;
    for (std::size_t i = 1; i < values.size(); ++i)
        if (values[i] < values[best]) best = i;

    // Golden-section search between the best point's neighbours.
    double lo = grid[best == 0 ? 0 : best - 1];
    double hi = grid[std::min(best + 1, grid.size() - 1)];
    double best_mu = grid[best], best_value = values[best];
    const double ratio = (std::sqrt(5.0) - 1) / 2;
    double x1 = hi - ratio * (hi - lo), x2 = lo + ratio * (hi - lo);
    double f1 = objective(x1), f2 = objective(x2);
    for (int iteration = 0; iteration < 12; ++iteration) {
        if (f1 < f2) {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - ratio * (hi - lo);
            f1 = objective(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + ratio * (hi - lo);
            f2 = objective(x2);
        }
    }
    for (const auto& [mu, value] : result.evaluated) {
        if (value < best_value) {
            best_value = value;
            best_mu = mu;
        }
    }
    result.mu = best_mu;
    result.divergence = best_value;
    return result;
}

std::string with_calibrated_friction(const std::string& toml_text, const std::string& file_name,
                                     const std::string& engine, const CalibrationResult& result) {
    const std::string value_line =
        fmt::format("friction = {:.6g}  # bouncecheck calibrate: RMS distance {:.3g} m from {}", result.mu,
                    result.divergence, baseline_name(result.baseline));
    const std::regex header("^\\s*\\[\\s*engines\\s*\\.\\s*" + engine + "\\s*\\]\\s*(#.*)?$");
    const std::regex any_header("^\\s*\\[.*$");
    const std::regex friction_key("^\\s*friction\\s*=.*$");

    std::vector<std::string> lines;
    std::istringstream in(toml_text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);

    bool in_table = false, done = false;
    std::size_t table_header = lines.size();
    for (std::size_t i = 0; i < lines.size() && !done; ++i) {
        if (std::regex_match(lines[i], header)) {
            in_table = true;
            table_header = i;
        } else if (in_table && std::regex_match(lines[i], any_header)) {
            break;
        } else if (in_table && std::regex_match(lines[i], friction_key)) {
            lines[i] = value_line;
            done = true;
        }
    }
    if (!done && table_header < lines.size()) {
        lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(table_header) + 1, value_line);
    } else if (!done) {
        lines.push_back("");
        lines.push_back(fmt::format("[engines.{}]", engine));
        lines.push_back(value_line);
    }
    std::string out;
    for (const auto& line : lines) out += line + "\n";
    parse_scenario(out, file_name);  // throws ScenarioError if the edit broke the file
    return out;
}

}  // namespace bouncecheck
