// What every engine shares: any engine may include it.
#pragma once
