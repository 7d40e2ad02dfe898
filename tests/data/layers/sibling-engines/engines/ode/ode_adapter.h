// An engine's own header.
#pragma once
#include "engines/engine.h"
