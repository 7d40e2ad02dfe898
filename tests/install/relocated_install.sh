#!/bin/sh
# `cmake --install` into a prefix, then the prefix moved elsewhere: the
# installed binary still finds every engine module and the bundled scenarios
# under its own prefix (platform/install_layout.h), never in the build tree,
# and runs the bundled scenarios with every engine's row ok.
#   relocated_install.sh BUILD_DIR
set -eu
build=$1
work=$(mktemp -d "${TMPDIR:-/tmp}/bouncecheck-install.XXXXXX")
trap 'rm -rf "$work"' EXIT INT TERM
fail() { echo "FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$work/first" >/dev/null
mv "$work/first" "$work/moved"
bin="$work/moved/bin/bouncecheck"
"$bin" list --json >"$work/list.json"
"$bin" run --no-timings --out "$work/out" >"$work/run.log" 2>&1 || fail "run exited $?: $(tail -5 "$work/run.log")"

python3 - "$work" "$work/moved" <<'PY' || exit 1
import json, sys
work, prefix = sys.argv[1], sys.argv[2]
listed = json.load(open(f"{work}/list.json"))
problems = []
if listed["scenario_dir"] != f"{prefix}/share/bouncecheck/scenarios":
    problems.append(f"scenarios from {listed['scenario_dir']}")
engines = [s for s in listed["simulators"] if "module" in s]
if not engines:
    problems.append("no engine module listed")
for s in engines:
    if not s["module"].startswith(f"{prefix}/lib/bouncecheck/engines/") or not s["module_found"]:
        problems.append(f"{s['name']}: module {s['module']} (found: {s['module_found']})")
report = json.load(open(f"{work}/out/report.json"))
ran = set()
for scenario in report["scenarios"]:
    for sim in scenario["simulators"]:
        if sim["status"] == "ok":
            ran.add(sim["simulator"])
        elif sim["status"] != "skipped":
            problems.append(f"{scenario['scenario']['name']} {sim['simulator']}: {sim['status']} {sim.get('reason', '')}")
for s in engines:
    if s["name"] not in ran:
        problems.append(f"{s['name']} ran no scenario")
if problems:
    print("FAIL:", *problems, sep="\n  ")
    sys.exit(1)
print(f"installed and moved: {len(engines)} engine modules and {len(listed['scenarios'])} scenarios found under "
      f"the new prefix; every engine ran")
PY
