#include "adapters/simulator.h"
#include "reference/simulators.h"

namespace bouncecheck {

std::vector<std::unique_ptr<const Simulator>> built_simulators() {
    std::vector<std::unique_ptr<const Simulator>> all;
    all.push_back(make_reference_simulator());
    all.push_back(make_exact_simulator());
    return all;
}

}  // namespace bouncecheck
