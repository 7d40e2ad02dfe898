#!/usr/bin/env bash
# The HTML pages in a real browser: runs `bouncecheck run` on the bundled
# scenarios and `bouncecheck sweep` on a short sweep, then opens report.html
# and sweep.html in headless Chromium (web/test/browser-check.mjs). The
# screenshots stay in ARTIFACTS for CI to keep.
# usage: check_pages.sh BOUNCECHECK WEB_DIR ARTIFACTS_DIR
set -euo pipefail
BIN="$1" WEB="$2" ARTIFACTS="$3"
mkdir -p "$ARTIFACTS"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

"$BIN" run --out "$out/run" > "$out/run.log" 2>&1 || { cat "$out/run.log"; echo "bouncecheck run failed"; exit 1; }
node "$WEB/test/browser-check.mjs" "$out/run/report.html" "$out/run/report.json" "$ARTIFACTS/report.png"
echo "report.html: $(stat -c %s "$out/run/report.html") bytes"

"$BIN" sweep "$WEB/../scenarios/seed-3d.toml" --dt 0.03:0.005:2 --repeat 1 --out "$out/sweep" > "$out/sweep.log" 2>&1 \
  || { cat "$out/sweep.log"; echo "bouncecheck sweep failed"; exit 1; }
node "$WEB/test/browser-check.mjs" "$out/sweep/sweep.html" "$out/sweep/sweep.json" "$ARTIFACTS/sweep.png"
echo "sweep.html: $(stat -c %s "$out/sweep/sweep.html") bytes"
