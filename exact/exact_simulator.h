// `exact`: the same damping law in continuous time, behind the simulator interface.
#pragma once

#include "simulators/simulator.h"

namespace bouncecheck {

std::unique_ptr<const Simulator> make_exact_simulator();

}  // namespace bouncecheck
