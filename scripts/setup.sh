#!/usr/bin/env bash
# Brings a fresh Debian 12 machine to a built bouncecheck: installs the Debian
# packages that are missing, configures and builds into build/ (or $BUILD_DIR).
# Run by scripts/run.sh, test.sh and sanitize.sh; arguments go to the CMake
# configure step (e.g. -DBOUNCECHECK_WITH_ODE=OFF). Safe to run again.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"

# Everything the build needs, from Debian 12's own packages.
PACKAGES=(
  build-essential cmake pkg-config
  libeigen3-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libfmt-dev libtbb-dev
  libgtest-dev libbenchmark-dev
  libbullet-dev libode-dev libbox2d-dev
)

"$ROOT/scripts/packages.sh" "${PACKAGES[@]}"

mkdir -p "$BUILD_DIR"
cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" "$@" > "$BUILD_DIR/configure.log" 2>&1 \
  || { cat "$BUILD_DIR/configure.log"; exit 1; }
cmake --build "$BUILD_DIR" -j "$(nproc)"
