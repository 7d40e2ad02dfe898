#include "adapters/simulator.h"
#include "reference/simulators.h"

namespace bouncecheck {

// Defined in adapters/<engine>/, compiled only when the engine is built.
std::unique_ptr<const Simulator> make_bullet_simulator();
std::unique_ptr<const Simulator> make_ode_simulator();
std::unique_ptr<const Simulator> make_box2d_simulator();

std::vector<std::unique_ptr<const Simulator>> built_simulators() {
    std::vector<std::unique_ptr<const Simulator>> all;
    all.push_back(make_reference_simulator());
    all.push_back(make_exact_simulator());
#ifdef BOUNCECHECK_WITH_BULLET
    all.push_back(make_bullet_simulator());
#endif
#ifdef BOUNCECHECK_WITH_ODE
    all.push_back(make_ode_simulator());
#endif
#ifdef BOUNCECHECK_WITH_BOX2D
    all.push_back(make_box2d_simulator());
#endif
    return all;
}

}  // namespace bouncecheck
