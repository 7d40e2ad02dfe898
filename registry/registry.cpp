#include "registry/registry.h"

#include "exact/exact_simulator.h"
#include "reference/reference_simulator.h"
#include "registry/engine_module.h"
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
#ifdef BOUNCECHECK_WITH_NODE_ENGINES
#include "registry/node_engines.h"
#endif

namespace bouncecheck {

namespace {

// Each engine this build has, and the folder of its adapter (its module's name).
struct BuiltEngine {
    const EngineIdentity* identity;
    const char* folder;
};

constexpr BuiltEngine kBuiltEngines[] = {
#ifdef BOUNCECHECK_WITH_BULLET
    {&bullet::kIdentity, "bullet"},
#endif
#ifdef BOUNCECHECK_WITH_ODE
    {&ode::kIdentity, "ode"},
#endif
#ifdef BOUNCECHECK_WITH_BOX2D
    {&box2d::kIdentity, "box2d"},
#endif
#ifdef BOUNCECHECK_WITH_MUJOCO
    {&mujoco::kIdentity, "mujoco"},
#endif
#ifdef BOUNCECHECK_WITH_CHIPMUNK
    {&chipmunk::kIdentity, "chipmunk"},
#endif
#ifdef BOUNCECHECK_WITH_SICONOS
    {&siconos::kTimeSteppingIdentity, "siconos"},
    {&siconos::kEventDrivenIdentity, "siconos"},
#endif
#ifdef BOUNCECHECK_WITH_DART
    {&dartsim::kIdentity, "dart"},
#endif
    {nullptr, nullptr},  // so that a build without engines has a table
};

}  // namespace

std::vector<std::unique_ptr<const Simulator>> built_simulators(ExternalLimits hosted) {
    std::vector<std::unique_ptr<const Simulator>> all;
    all.push_back(make_reference_simulator());
    all.push_back(make_exact_simulator());
    for (const BuiltEngine& engine : kBuiltEngines)
        if (engine.identity) all.push_back(engine_in_module(*engine.identity, engine.folder));
#ifdef BOUNCECHECK_WITH_NODE_ENGINES
    for (auto& node_engine : make_node_engine_simulators(hosted)) all.push_back(std::move(node_engine));
#else
    (void)hosted;
#endif
    return all;
}

std::vector<EngineModule> engine_modules() {
    std::vector<EngineModule> modules;
    for (const BuiltEngine& engine : kBuiltEngines)
        if (engine.identity) modules.push_back({std::string(engine.identity->name), engine_module_file(engine.folder)});
    return modules;
}

}  // namespace bouncecheck
