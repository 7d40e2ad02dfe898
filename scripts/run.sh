#!/usr/bin/env bash
# Quick start 1: set up, build, and run the main job — `bouncecheck run` on the
# bundled scenarios. Extra arguments go to `bouncecheck run`.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$ROOT/scripts/setup.sh"
exec "${BUILD_DIR:-$ROOT/build}/bouncecheck" run "$@"
