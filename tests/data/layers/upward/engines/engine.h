// An engine that includes the reference: siblings must not know each other.
#pragma once
#include "reference/reference_model.h"
