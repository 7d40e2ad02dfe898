#!/usr/bin/env bash
# Quick start 2: set up, build, and run the whole test suite through CTest.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WITH_TEST_TOOLS=1 "$ROOT/scripts/setup.sh"
cd "${BUILD_DIR:-$ROOT/build}"
exec ctest --output-on-failure -j "$(nproc)" "$@"
