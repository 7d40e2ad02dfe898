// A simulator header that reaches up into the metrics: the rule must catch it.
#pragma once
#include "metrics/summary.h"
