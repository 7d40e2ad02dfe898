// What the engine test files (tests/test_<engine>.cpp) share: the bundled
// seeds without their engine tables, a run with every state kept, a setting
// as reported, the floor contacts of a 2D run, and the first floor contact
// of a run and of exact.
#pragma once

#include "exact/exact_model.h"
#include "metrics/summary.h"
#include "scenarios/loader.h"
#include "simulators/simulator.h"
#include "tests/support/engine_run.h"

#include <algorithm>
#include <cmath>
#include <optional>
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

// The time of exact's first contact with the floor (vertical axis z, lower side); -1 if none.
inline double first_exact_floor_contact(const ExactModel& exact, int z) {
    for (const WallContact& c : exact.contacts())
        if (c.axis == z && c.side < 0) return c.t;
    return -1;
}

// The time of the first floor contact a run's stream showed.
inline std::optional<double> first_floor_event(const SimulatorSummary& r, int z) {
    for (const ContactEvent& e : r.contact_events)
        if (e.axis == z && e.side < 0) return e.t;
    return std::nullopt;
}

}  // namespace bouncecheck::test
