#pragma once
#include "simulators/simulator.h"
