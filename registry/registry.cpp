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

namespace bouncecheck {

std::vector<std::unique_ptr<const Simulator>> built_simulators() {
    std::vector<std::unique_ptr<const Simulator>> all;
    all.push_back(make_reference_simulator());
    all.push_back(make_exact_simulator());
#ifdef BOUNCECHECK_WITH_BULLET
    all.push_back(engine_in_module(bullet::kIdentity, "bullet"));
#endif
#ifdef BOUNCECHECK_WITH_ODE
    all.push_back(engine_in_module(ode::kIdentity, "ode"));
#endif
#ifdef BOUNCECHECK_WITH_BOX2D
    all.push_back(engine_in_module(box2d::kIdentity, "box2d"));
#endif
#ifdef BOUNCECHECK_WITH_MUJOCO
    all.push_back(engine_in_module(mujoco::kIdentity, "mujoco"));
#endif
#ifdef BOUNCECHECK_WITH_CHIPMUNK
    all.push_back(engine_in_module(chipmunk::kIdentity, "chipmunk"));
#endif
#ifdef BOUNCECHECK_WITH_SICONOS
    all.push_back(engine_in_module(siconos::kTimeSteppingIdentity, "siconos"));
    all.push_back(engine_in_module(siconos::kEventDrivenIdentity, "siconos"));
#endif
#ifdef BOUNCECHECK_WITH_DART
    all.push_back(engine_in_module(dartsim::kIdentity, "dart"));
#endif
    return all;
}

}  // namespace bouncecheck
