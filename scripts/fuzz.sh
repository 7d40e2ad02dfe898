#!/usr/bin/env bash
# Fuzzes the scenario loader (parse + validation, as `bouncecheck validate`)
# with libFuzzer under ASan and UBSan for a bounded time:
#
#   scripts/fuzz.sh [SECONDS]      # default 300
#
# Installs what is missing (clang 14 and its libFuzzer/sanitizer runtimes),
# builds fuzz/ into build-fuzz/ (or $FUZZ_BUILD_DIR), and runs on one core.
# The corpus grows in build-fuzz/corpus/ from run to run; each run is seeded
# afresh with the bundled scenarios, the broken ones under tests/data/invalid/
# and fuzz/seeds/. Fails on any finding: the input is kept in
# build-fuzz/findings/ (reproduce: build-fuzz/fuzz/fuzz_scenario_loader FILE).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${FUZZ_BUILD_DIR:-$ROOT/build-fuzz}"
SECONDS_TO_RUN="${1:-300}"
[[ "$SECONDS_TO_RUN" =~ ^[1-9][0-9]*$ ]] || { echo "usage: scripts/fuzz.sh [SECONDS]" >&2; exit 2; }

# The top-level CMake project finds every library before it knows it only
# builds the fuzz target, so those are needed too (the engines are not).
"$ROOT/scripts/packages.sh" build-essential cmake pkg-config clang-14 libclang-rt-14-dev \
  libeigen3-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libfmt-dev

mkdir -p "$BUILD_DIR"
cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
  -DBOUNCECHECK_BUILD_FUZZ=ON -DBOUNCECHECK_BUILD_TESTS=OFF -DBOUNCECHECK_BUILD_BENCH=OFF \
  -DBOUNCECHECK_WITH_BULLET=OFF -DBOUNCECHECK_WITH_ODE=OFF -DBOUNCECHECK_WITH_BOX2D=OFF \
  -DBOUNCECHECK_WITH_MUJOCO=OFF -DBOUNCECHECK_WITH_CHIPMUNK=OFF -DBOUNCECHECK_WITH_SICONOS=OFF -DBOUNCECHECK_WITH_DART=OFF \
  > "$BUILD_DIR/configure.log" 2>&1 || { cat "$BUILD_DIR/configure.log"; exit 1; }
cmake --build "$BUILD_DIR" --target fuzz_scenario_loader -j "$(nproc)"

seeds="$BUILD_DIR/seeds"
rm -rf "$seeds"
rm -rf "$BUILD_DIR/findings"  # only this run's
mkdir -p "$seeds" "$BUILD_DIR/corpus" "$BUILD_DIR/findings"
cp "$ROOT"/scenarios/*.toml "$seeds/"
for f in "$ROOT"/tests/data/invalid/*.toml; do cp "$f" "$seeds/invalid-$(basename "$f")"; done
for f in "$ROOT"/fuzz/seeds/*; do cp "$f" "$seeds/fuzz-$(basename "$f")"; done

# One process on one core. -timeout turns a hang (an input taking over 10 s)
# into a finding; -rss_limit_mb does the same for runaway memory.
echo "fuzz: running for ${SECONDS_TO_RUN} s; log in $BUILD_DIR/fuzz.log"
status=0
"$BUILD_DIR/fuzz/fuzz_scenario_loader" "$BUILD_DIR/corpus" "$seeds" \
  -dict="$ROOT/fuzz/toml.dict" -max_total_time="$SECONDS_TO_RUN" -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix="$BUILD_DIR/findings/" -print_final_stats=1 \
  > "$BUILD_DIR/fuzz.log" 2>&1 || status=$?
# The summary: the last status line (executions, coverage "cov", corpus
# "corp" after libFuzzer's own reduction), and the final counts.
grep -E '^#[0-9]+' "$BUILD_DIR/fuzz.log" | tail -n 1 || true
grep -E '^(Done|stat::number_of_executed_units|stat::peak_rss_mb)' "$BUILD_DIR/fuzz.log" || true
if ((status != 0)); then
  tail -n 60 "$BUILD_DIR/fuzz.log"
  echo "fuzz: failed (exit $status); findings in $BUILD_DIR/findings/:" >&2
  ls -1 "$BUILD_DIR/findings/" >&2
  exit 1
fi
echo "fuzz: no finding"
