#!/bin/sh
# The C++ API from outside the build, as an engine's own project uses it:
# `cmake --install` into a prefix, then examples/cmake-consumer configured
# against it with find_package(bouncecheck CONFIG) alone, built, and its
# tests run; its deliberately wrong toy (alpha 0.7 on a 0.8 scenario) must
# fail, with each failed check and the harness's table in the output.
#   cmake_consumer.sh SOURCE_DIR BUILD_DIR
set -eu
src=$1 build=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/bouncecheck-consumer.XXXXXX")
trap 'rm -rf "$work"' EXIT INT TERM
fail() { echo "FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$work/prefix" >/dev/null
# The consumer compiles and links with the flags the library was built with
# (none in a plain build; ASan and UBSan's under scripts/sanitize.sh, whose
# instrumented archive needs their runtimes).
cache() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }
cmake -S "$src/examples/cmake-consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_CXX_FLAGS="$(cache CMAKE_CXX_FLAGS)" -DCMAKE_EXE_LINKER_FLAGS="$(cache CMAKE_EXE_LINKER_FLAGS)" \
  >"$work/configure.log" 2>&1 || { cat "$work/configure.log"; fail "the consumer does not configure"; }
cmake --build "$work/consumer" -j 2 >"$work/build.log" 2>&1 || { tail -40 "$work/build.log"; fail "the consumer does not build"; }
ctest --test-dir "$work/consumer" --output-on-failure >"$work/ctest.log" 2>&1 || { cat "$work/ctest.log"; fail "its tests failed"; }
grep -E "tests passed" "$work/ctest.log"

status=0
"$work/consumer/consumer_tests" --gtest_also_run_disabled_tests --gtest_filter='*WrongAlpha*' >"$work/wrong.log" 2>&1 || status=$?
[ "$status" -ne 0 ] || { cat "$work/wrong.log"; fail "the wrong toy passed"; }
for expected in "does not follow the law" "apex err" "damping: "; do
  grep -q "$expected" "$work/wrong.log" || { cat "$work/wrong.log"; fail "the wrong toy's failure does not show '$expected'"; }
done
echo "the consumer built against the installed package and its tests passed; the wrong toy failed (exit $status) with its reasons and the table"
