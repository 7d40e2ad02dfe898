// What the engine test files (tests/test_<engine>.cpp) share: the bundled
// seeds without their engine tables, a run with every state kept, a setting
// as reported, and the floor contacts of a 2D run.
#pragma once

#include "metrics/summary.h"
#include "scenarios/loader.h"
#include "simulators/simulator.h"
#include "tests/support/engine_run.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace bouncecheck::test {

// A bundled scenario with its [engines] tables (calibrated friction) dropped:
// each test sets the engine options it is about.
inline Scenario bundled_seed(const std::string& file) {
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + file);
    s.engines.clear();
    return s;
}

// `sim` through record_run, every state kept.
inline SimulatorRun record_states(const Simulator& sim, const Scenario& s) {
    StateVector sink;
    SimulatorRun run;
    run.summary = record_run(sim, s, &sink);
    run.states = std::move(sink.states);
    return run;
}

// A setting as the simulator reported it: its value, or its reason.
inline const Setting* find_setting(const std::vector<Setting>& settings, const std::string& key) {
    const auto it = std::find_if(settings.begin(), settings.end(), [&](const Setting& st) { return st.key == key; });
    return it == settings.end() ? nullptr : &*it;
}
inline std::string setting(const std::vector<Setting>& settings, const std::string& key) {
    const Setting* st = find_setting(settings, key);
    return st ? st->value : "<missing " + key + ">";
}
inline std::string setting(const SimulatorSummary& summary, const std::string& key) {
    return setting(summary.settings, key);
}
inline std::string setting_why(const SimulatorSummary& summary, const std::string& key) {
    const Setting* st = find_setting(summary.settings, key);
    return st ? st->why : "<missing " + key + ">";
}

// A floor contact seen in a 2D stream (the framework's detector rule for the
// floor): the samples just before and just after it.
struct FloorHit {
    State before, after;
    double restitution() const { return -after.v.y() / before.v.y(); }
    double min_height() const { return std::min(before.p.y(), after.p.y()); }
};

inline std::vector<FloorHit> floor_hits(const std::vector<State>& st, double r) {
    std::vector<FloorHit> out;
    for (std::size_t i = 1; i < st.size(); ++i) {
        const State& a = st[i - 1];
        const State& b = st[i];
        const double reach = std::abs(a.v.y()) * (b.t - a.t) + 0.1 * r;
        if (a.v.y() < 0 && b.v.y() >= 0 && b.p.y() - r <= reach) out.push_back({a, b});
    }
    return out;
}

}  // namespace bouncecheck::test
