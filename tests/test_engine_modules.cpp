// The registry holds each engine as its identity and loads the adapter's
// module (registry/engine_module.h) only when a run needs the engine: the
// module it loads is the right adapter, a command that runs no engine loads
// no engine library, and a module that cannot be loaded costs only its engine.
#include "registry/engine_module.h"
#include "registry/registry.h"
#include "tests/support/cli.h"
#include "tests/support/engine_tests.h"
#include "tests/support/test_directory.h"

#ifdef BOUNCECHECK_WITH_BULLET
#include "engines/bullet/bullet_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_ODE
#include "engines/ode/ode_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_BOX2D
#include "engines/box2d/box2d_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_MUJOCO
#include "engines/mujoco/mujoco_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_CHIPMUNK
#include "engines/chipmunk/chipmunk_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_SICONOS
#include "engines/siconos/siconos_adapter.h"
#endif
#ifdef BOUNCECHECK_WITH_DART
#include "engines/dart/dart_adapter.h"
#endif

#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <map>

namespace bouncecheck {
namespace {

// Every built engine's adapter, linked into the tests directly.
std::map<std::string, std::function<std::unique_ptr<const Simulator>()>> linked_adapters() {
    std::map<std::string, std::function<std::unique_ptr<const Simulator>()>> all;
#ifdef BOUNCECHECK_WITH_BULLET
    all["bullet"] = make_bullet_simulator;
#endif
#ifdef BOUNCECHECK_WITH_ODE
    all["ode"] = make_ode_simulator;
#endif
#ifdef BOUNCECHECK_WITH_BOX2D
    all["box2d"] = make_box2d_simulator;
#endif
#ifdef BOUNCECHECK_WITH_MUJOCO
    all["mujoco"] = make_mujoco_simulator;
#endif
#ifdef BOUNCECHECK_WITH_CHIPMUNK
    all["chipmunk"] = make_chipmunk_simulator;
#endif
#ifdef BOUNCECHECK_WITH_SICONOS
    all["siconos"] = make_siconos_simulator;
    all["siconos-ed"] = make_siconos_event_driven_simulator;
#endif
#ifdef BOUNCECHECK_WITH_DART
    all["dart"] = make_dart_simulator;
#endif
    return all;
}

// Each registered engine, once loaded, is its own adapter: the same
// identity, the same refusals, and a run with the same settings and states
// as the adapter linked here.
TEST(EngineModules, EachRegisteredEngineRunsItsOwnAdapter) {
    const auto adapters = linked_adapters();
    Scenario friction = test::bundled_seed("seed-2d.toml");
    friction.engines["siconos-ed"].tangential_model = TangentialModel::friction;
    friction.engines["siconos-ed"].friction = 0.3;
    std::size_t engines = 0;
    for (const auto& registered : built_simulators()) {
        if (!registered->third_party() || !registered->origin().empty()) continue;  // the Node-hosted: programs
        const std::string name(registered->name());
        SCOPED_TRACE(name);
        ASSERT_EQ(adapters.count(name), 1u);
        const auto linked = adapters.at(name)();
        ++engines;
        EXPECT_EQ(registered->description(), linked->description());
        EXPECT_EQ(registered->typical_ns_per_step(), linked->typical_ns_per_step());
        EXPECT_EQ(registered->cannot_run(friction), linked->cannot_run(friction));
        const Scenario s = test::bundled_seed(linked->cannot_run(test::bundled_seed("seed-3d.toml")) ? "seed-2d.toml"
                                                                                                     : "seed-3d.toml");
        ASSERT_EQ(registered->cannot_run(s), std::nullopt);
        const test::SimulatorRun a = test::record_states(*registered, s), b = test::record_states(*linked, s);
        ASSERT_EQ(a.summary.status, RunStatus::ok) << a.summary.reason;
        ASSERT_EQ(a.states.size(), b.states.size());
        EXPECT_EQ(a.states.back().p, b.states.back().p);
        EXPECT_EQ(a.states.back().v, b.states.back().v);
        ASSERT_EQ(a.summary.settings.size(), b.summary.settings.size());
        for (std::size_t i = 0; i < a.summary.settings.size(); ++i) {
            EXPECT_EQ(a.summary.settings[i].key, b.summary.settings[i].key);
            EXPECT_EQ(a.summary.settings[i].value, b.summary.settings[i].value);
        }
    }
    EXPECT_EQ(engines, adapters.size());
}

class EngineModulesCli : public test::TestDirectory {
protected:
    // What `bouncecheck run SCENARIO --engines ENGINES` printed, with what the dynamic loader
    // reported loading (LD_DEBUG=files), in its worker processes too.
    std::string libraries_loaded_by_run(const std::string& scenario, const std::string& engines) const {
        ::setenv("LD_DEBUG", "files", 1);
        const test::CliResult r = test::bouncecheck("run " + std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + scenario +
                                                    " --engines " + engines + " --out " + (dir_ / engines).string());
        ::unsetenv("LD_DEBUG");
        EXPECT_EQ(r.status, 0) << r.output;
        return r.output;
    }
};

TEST_F(EngineModulesCli, ARunLoadsOnlyTheEnginesItRuns) {
    const std::string no_engine = libraries_loaded_by_run("seed-3d.toml", "reference,exact");
    EXPECT_NE(no_engine.find("libfmt"), std::string::npos) << "LD_DEBUG=files reported nothing:\n" << no_engine;
    EXPECT_EQ(no_engine.find("bouncecheck-engine-"), std::string::npos) << no_engine;
    EXPECT_EQ(no_engine.find("libode"), std::string::npos);
    EXPECT_EQ(no_engine.find("libdart"), std::string::npos);

#ifdef BOUNCECHECK_WITH_ODE
    const std::string ode = libraries_loaded_by_run("seed-3d.toml", "reference,ode");
    EXPECT_NE(ode.find("bouncecheck-engine-ode.so"), std::string::npos) << ode;
    EXPECT_NE(ode.find("libode"), std::string::npos);
    EXPECT_EQ(ode.find("bouncecheck-engine-dart"), std::string::npos);
    EXPECT_EQ(ode.find("libdart"), std::string::npos);
#endif
}

// A module that is missing, or lacks the engine's entry: that engine cannot
// run, says why, and nothing is thrown.
TEST(EngineModules, AnEngineWhoseModuleCannotBeLoadedSaysWhy) {
    const Scenario s = test::bundled_seed("seed-3d.toml");
    const EngineIdentity ghost{"ghost", "no such engine", 100};

    const auto missing = engine_in_module(ghost, "ghost");
    EXPECT_EQ(missing->name(), "ghost");
    EXPECT_EQ(missing->description(), "no such engine");
    EXPECT_EQ(missing->typical_ns_per_step(), 100);
    EXPECT_TRUE(missing->third_party());
    const auto why = missing->cannot_run(s);
    ASSERT_TRUE(why.has_value());
    EXPECT_NE(why->find("cannot load the engine's module"), std::string::npos) << *why;
    EXPECT_NE(why->find("bouncecheck-engine-ghost.so"), std::string::npos) << *why;
    struct Discard final : RunSink {
        bool on_state(const State&, ContactMask) override { return true; }
        void on_periodic_tail(const PeriodicTail&) override {}
    } sink;
    const RunOutcome run = missing->run(s, sink);
    EXPECT_EQ(run.status, RunStatus::failed);
    EXPECT_EQ(run.reason, *why);
    const UnrecordedRun unrecorded = missing->run_unrecorded(s);
    EXPECT_EQ(unrecorded.status, RunStatus::failed);
    EXPECT_EQ(unrecorded.reason, *why);

#ifdef BOUNCECHECK_WITH_ODE
    const auto no_entry = engine_in_module(ghost, "ode");
    const auto no_entry_why = no_entry->cannot_run(s);
    ASSERT_TRUE(no_entry_why.has_value());
    EXPECT_NE(no_entry_why->find("has no entry bouncecheck_engine_ghost"), std::string::npos) << *no_entry_why;
#endif
}

}  // namespace
}  // namespace bouncecheck
