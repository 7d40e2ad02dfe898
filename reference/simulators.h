#pragma once

#include "adapters/simulator.h"

namespace bouncecheck {

std::unique_ptr<const Simulator> make_reference_simulator();
std::unique_ptr<const Simulator> make_exact_simulator();

}  // namespace bouncecheck
