#!/usr/bin/env bash
# Fuzzes bouncecheck's readers with libFuzzer under ASan and UBSan, each for
# a bounded time, one after another:
#   fuzz_scenario_loader   the scenario loader (parse + validation, as `bouncecheck validate`)
#   fuzz_output_manifest   an output folder's manifest (bouncecheck-manifest.tsv)
#   fuzz_cbor_check        the check before merge decodes a shard file's CBOR, and the decoder after it
#   fuzz_trajectory_reader an external program's streamed trajectory, or an imported --trajectory file
#   fuzz_diff_report       diff's report reader (report.json), and the diff of what it loads
#   fuzz_external_settings an external program's settings file
#
#   scripts/fuzz.sh [SECONDS]      # per target; default 300
#
# Installs what is missing (clang 14 and its libFuzzer/sanitizer runtimes),
# builds fuzz/ into build-fuzz/ (or $FUZZ_BUILD_DIR), and runs on one core.
# Each target's corpus grows in build-fuzz/corpus/<target>/ from run to run;
# each run is seeded afresh: the loader with the bundled scenarios, the
# broken ones under tests/data/invalid/ and fuzz/seeds/; the manifest with
# fuzz/seeds-manifest/; the CBOR check with fuzz/seeds-cbor/; the
# trajectory reader with fuzz/seeds-trajectory/; the report reader with
# fuzz/seeds-report/; the settings reader with fuzz/seeds-settings/. Fails on
# any finding: the input is kept in build-fuzz/findings/<target>/
# (reproduce: build-fuzz/fuzz/<target> FILE).
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
  -DBOUNCECHECK_WITH_NODE_ENGINES=OFF \
  > "$BUILD_DIR/configure.log" 2>&1 || { cat "$BUILD_DIR/configure.log"; exit 1; }
cmake --build "$BUILD_DIR" --target fuzz_scenario_loader fuzz_output_manifest fuzz_cbor_check \
  fuzz_trajectory_reader fuzz_diff_report fuzz_external_settings -j "$(nproc)"

# fuzz TARGET SEED_DIR [-dict=FILE]: one process on one core for SECONDS_TO_RUN.
# -timeout turns a hang (an input taking over 10 s) into a finding;
# -rss_limit_mb does the same for runaway memory.
failed=0
fuzz() {
  local target="$1" seeds="$2" status=0
  shift 2
  local corpus="$BUILD_DIR/corpus/$target" findings="$BUILD_DIR/findings/$target" log="$BUILD_DIR/$target.log"
  rm -rf "$findings"  # only this run's
  mkdir -p "$corpus" "$findings"
  echo "fuzz: $target for ${SECONDS_TO_RUN} s; log in $log"
  "$BUILD_DIR/fuzz/$target" "$corpus" "$seeds" "$@" -max_total_time="$SECONDS_TO_RUN" -timeout=10 \
    -rss_limit_mb=2048 -artifact_prefix="$findings/" -print_final_stats=1 > "$log" 2>&1 || status=$?
  # The summary: the last status line (executions, coverage "cov", corpus
  # "corp" after libFuzzer's own reduction), and the final counts.
  grep -E '^#[0-9]+' "$log" | tail -n 1 || true
  grep -E '^(Done|stat::number_of_executed_units|stat::peak_rss_mb)' "$log" || true
  if ((status != 0)); then
    tail -n 60 "$log"
    echo "fuzz: $target failed (exit $status); findings in $findings/:" >&2
    ls -1 "$findings/" >&2
    failed=1
  fi
}

seeds="$BUILD_DIR/seeds/scenario-loader"
rm -rf "$BUILD_DIR/seeds"
mkdir -p "$seeds"
cp "$ROOT"/scenarios/*.toml "$seeds/"
for f in "$ROOT"/tests/data/invalid/*.toml; do cp "$f" "$seeds/invalid-$(basename "$f")"; done
for f in "$ROOT"/fuzz/seeds/*; do cp "$f" "$seeds/fuzz-$(basename "$f")"; done
fuzz fuzz_scenario_loader "$seeds" -dict="$ROOT/fuzz/toml.dict"
fuzz fuzz_output_manifest "$ROOT/fuzz/seeds-manifest"
fuzz fuzz_cbor_check "$ROOT/fuzz/seeds-cbor"
fuzz fuzz_trajectory_reader "$ROOT/fuzz/seeds-trajectory"
fuzz fuzz_diff_report "$ROOT/fuzz/seeds-report"
fuzz fuzz_external_settings "$ROOT/fuzz/seeds-settings"

((failed == 0)) || exit 1
echo "fuzz: no finding"
