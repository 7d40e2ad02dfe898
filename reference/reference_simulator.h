// `reference`: the seed document's model behind the simulator interface.
#pragma once

#include "simulators/simulator.h"

namespace bouncecheck {

std::unique_ptr<const Simulator> make_reference_simulator();

}  // namespace bouncecheck
