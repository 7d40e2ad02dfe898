#!/usr/bin/env bash
# Brings a fresh Debian 12 machine to a built bouncecheck: installs the Debian
# packages that are missing, configures and builds into build/ (or $BUILD_DIR).
# Run by scripts/run.sh, test.sh and sanitize.sh; arguments go to the CMake
# configure step (e.g. -DBOUNCECHECK_WITH_DART=OFF, which also skips DART's
# packages: a lean build). Safe to run again.
# WITH_TEST_TOOLS=1 (scripts/test.sh sets it) also installs what only the
# tests run: Debian's chromium, for the test that opens the HTML pages in a
# real browser; python3, for the example external simulator
# (examples/external/semi_implicit_euler.py) and the sharded runs' comparison
# (tests/slurm/same_apart_from_timings.py); and slurm-wlm and munge, for the
# test that runs sharded stress and sweep runs through a single-node Slurm it
# starts itself (tests/slurm/slurm_test.sh; installing them starts no daemon
# that needs systemd, and the test uses its own configuration, not /etc's).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"

# Everything the build needs, from Debian 12's own packages.
PACKAGES=(
  build-essential cmake pkg-config
  libeigen3-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  libgtest-dev libbenchmark-dev
)
# Each engine's packages, left out when its CMake option is off: given here
# (-DBOUNCECHECK_WITH_DART=OFF) or kept in the build's cache from an earlier
# configure, so a lean build installs none of what it does not build.
declare -A ENGINE_PACKAGES=(
  [BULLET]="libbullet-dev" [ODE]="libode-dev" [BOX2D]="libbox2d-dev" [CHIPMUNK]="libchipmunk-dev"
  # Debian's mujocoConfig.cmake calls find_dependency(OpenGL), which needs the
  # GL headers and the libOpenGL/libGLX links, but libmujoco-dev does not
  # depend on them. bouncecheck never draws; they only let CMake load MuJoCo.
  [MUJOCO]="libmujoco-dev libgl-dev libopengl-dev"
  # Siconos 4.4's kernel and numerics (about 55 packages on a fresh root, SuiteSparse and Boost's headers).
  [SICONOS]="libsiconos-kernel-dev"
  # DART 6.12, core only. About 175 packages on a fresh root (Boost, OpenMPI, gfortran).
  [DART]="libdart-dev"
)
engine_enabled() {
  local option="BOUNCECHECK_WITH_$1" arg
  shift
  for arg in "$@"; do
    [[ "$arg" =~ ^-D${option}(:BOOL)?=(OFF|0|FALSE|NO)$ ]] && return 1
    [[ "$arg" =~ ^-D${option}(:BOOL)?= ]] && return 0
  done
  ! grep -qE "^${option}:BOOL=(OFF|0|FALSE|NO)$" "$BUILD_DIR/CMakeCache.txt" 2>/dev/null
}
for engine in "${!ENGINE_PACKAGES[@]}"; do
  # shellcheck disable=SC2206  # the value is a space-separated package list
  engine_enabled "$engine" "$@" && PACKAGES+=(${ENGINE_PACKAGES[$engine]})
done
# Node.js and npm install the charting library the HTML pages inline
# (web/package-lock.json; every package in it accepts Debian 12's Node 18 and
# npm 9, and web/.npmrc makes npm refuse one that does not). A machine that
# already has node and npm keeps them. npm fetches over HTTPS: a fresh
# minimal Debian has no CA bundle without ca-certificates.
command -v node >/dev/null && command -v npm >/dev/null || PACKAGES+=(nodejs npm)
PACKAGES+=(ca-certificates)
[ "${WITH_TEST_TOOLS:-0}" = 1 ] && PACKAGES+=(chromium python3 slurm-wlm munge)

"$ROOT/scripts/packages.sh" "${PACKAGES[@]}"

# node_modules from each lock file, again only when the lock file changed:
# web/ (the charting library) and, unless the build leaves them out,
# engines/node/ (the WebAssembly engines, pinned exactly).
npm_ci() {
  local folder="$1" lock_hash
  lock_hash="$(sha256sum "$folder/package-lock.json" | cut -d' ' -f1)"
  if [ "$(cat "$folder/node_modules/.bouncecheck-lock" 2>/dev/null)" != "$lock_hash" ]; then
    echo "setup: npm ci in ${folder#"$ROOT"/}/"
    (cd "$folder" && npm ci --no-audit --no-fund --loglevel=error)
    echo "$lock_hash" > "$folder/node_modules/.bouncecheck-lock"
  fi
}
npm_ci "$ROOT/web"
engine_enabled NODE_ENGINES "$@" && npm_ci "$ROOT/engines/node"

mkdir -p "$BUILD_DIR"
cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" "$@" > "$BUILD_DIR/configure.log" 2>&1 \
  || { cat "$BUILD_DIR/configure.log"; exit 1; }
cmake --build "$BUILD_DIR" -j "$(nproc)"
