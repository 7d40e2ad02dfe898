#!/usr/bin/env bash
# The whole project (engines, tests, benchmarks) built with gcc's
# AddressSanitizer and UndefinedBehaviorSanitizer into build-asan/ (or
# $ASAN_BUILD_DIR), then the whole CTest suite run there. A sanitizer report
# ends the process that made it, which fails its test. Arguments go to ctest.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${ASAN_BUILD_DIR:-$ROOT/build-asan}"
FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
# gcc 12 warns falsely inside libstdc++'s <regex> once it is instrumented
# (-Wmaybe-uninitialized); the normal build keeps that warning for our code.
FLAGS+=" -Wno-maybe-uninitialized"

# setup.sh installs what is missing; RelWithDebInfo keeps the suite's speed
# and gives reports file and line.
BUILD_DIR="$BUILD_DIR" BUILD_TYPE=RelWithDebInfo "$ROOT/scripts/setup.sh" \
  -DCMAKE_CXX_FLAGS="$FLAGS" -DCMAKE_EXE_LINKER_FLAGS="$FLAGS" -DCMAKE_SHARED_LINKER_FLAGS="$FLAGS" \
  -DCMAKE_MODULE_LINKER_FLAGS="$FLAGS"

# Exit status 99 on a report, which no bouncecheck status (0-3) can be
# mistaken for by the CLI tests.
export ASAN_OPTIONS="exitcode=99:detect_leaks=1:strict_string_checks=1:check_initialization_order=1"
# Siconos 4.4 leaks each simulation's object graph inside the library: named
# and explained in the suppressions file, every other leak still fails.
export LSAN_OPTIONS="suppressions=$ROOT/scripts/lsan-suppressions.txt:print_suppressions=0"
export UBSAN_OPTIONS="exitcode=99:print_stacktrace=1:halt_on_error=1"
cd "$BUILD_DIR"
exec ctest --output-on-failure -j "$(nproc)" "$@"
