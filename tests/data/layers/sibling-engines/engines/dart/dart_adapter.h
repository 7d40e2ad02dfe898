// An engine that includes another engine's header: engines must not know each other.
#pragma once
#include "engines/engine.h"
#include "engines/ode/ode_adapter.h"
