#!/usr/bin/env python3
"""A bouncecheck external simulator: semi-implicit (velocity-first) Euler.

Protocol bouncecheck-external/1 (docs/external.md): reads one JSON scenario
on stdin, writes the trajectory as CSV on stdout, then the `#end` line with
the time its steps took (so that bouncecheck charges it for its steps, not
for Python's start-up or its printing), and its settings as JSON to the
file `settings_file` names. Python 3 standard library only.

    bouncecheck run --external 'semi-implicit=python3 /abs/path/semi_implicit_euler.py'
    bouncecheck stress --external-session 'semi-implicit=python3 /abs/path/semi_implicit_euler.py --session'

With --session it answers scenario after scenario in one process (one JSON
scenario per input line), so that Python's start-up is paid once per worker.

The step: v += g*dt, then p += v*dt (the document's reference moves with the
old velocity first; this one uses the new one). Then the law's damping, per
contact: for each wall the centre has passed (p[i] < r or p[i] > room[i] - r)
while the velocity moves into it, the normal component is reversed and
scaled by alpha; if any wall was touched, every component normal to no
touched wall is scaled by beta, once (at a corner each touched wall reverses
its own component).

Position at contact: a centre beyond a wall is put back on it (p[i] = r or
room[i] - r), as the reference clamps it (EulersPosition). So the ball never
overlaps a wall in a sample, its centre stays within [r, room - r], and the
next step starts from the wall rather than from inside it.

The optional [engines.NAME] table of the scenario arrives as `engine`; this
program reads one key from it, `substeps` (integer >= 1, default 1: steps of
dt / substeps per sample), and ignores every other.
"""

import json
import math
import os
import sys
import time

CHUNK_ROWS = 4096  # rows per write: buffered, not flushed row by row


def fail(message):
    """The harness shows our last stderr lines as the failure's reason."""
    print(f"semi_implicit_euler.py: {message}", file=sys.stderr)
    sys.exit(1)


def read_scenario(text):
    try:
        scenario = json.loads(text)
    except json.JSONDecodeError as e:
        fail(f"standard input is not JSON: {e}")
    if not isinstance(scenario, dict) or scenario.get("protocol") != 1:
        fail("expected a JSON object with \"protocol\": 1 (bouncecheck-external/1)")
    return scenario


def substeps_of(engine):
    n = engine.get("substeps", 1) if isinstance(engine, dict) else 1
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        fail(f"engine.substeps must be an integer >= 1, got {n!r}")
    return n


def write_settings(path, substeps):
    settings = [
        {"key": "engine", "value": "semi_implicit_euler.py (Python " + sys.version.split()[0] + ")",
         "why": "the example external simulator of examples/external/"},
        {"key": "integrator", "value": "semi-implicit Euler",
         "why": "v += g dt, then p += v dt: the new velocity moves the ball"},
        {"key": "contact", "value": "per-contact damping",
         "why": "normal component reversed and scaled by alpha, every other scaled by beta, once per step"},
        {"key": "contact_test", "value": "centre beyond r of a wall, moving into it",
         "why": "a ball leaving a wall is not bounced back into it"},
        {"key": "position_at_contact", "value": "on the wall (centre at r)",
         "why": "as the reference clamps it: no sample overlaps a wall"},
        {"key": "substeps", "value": substeps, "why": "engine.substeps (default 1)"},
    ]
    with open(path, "w", encoding="utf-8") as f:
        json.dump(settings, f, indent=1)


def run(sc):
    dim = int(sc["dimension"])
    room = [float(x) for x in sc["room"]]
    r = float(sc["radius"])
    p = [float(x) for x in sc["position"]]
    v = [float(x) for x in sc["velocity"]]
    g = [float(x) for x in sc["gravity"]]
    alpha, beta = float(sc["alpha"]), float(sc["beta"])
    dt, duration = float(sc["dt"]), float(sc["duration"])
    steps = int(sc["steps"])
    if dim not in (2, 3) or not all(len(x) == dim for x in (room, p, v, g)):
        fail(f"dimension {dim} and the vectors' lengths disagree")
    substeps = substeps_of(sc.get("engine", {}))
    if sc.get("settings_file"):
        write_settings(sc["settings_file"], substeps)

    h = dt / substeps
    low = [r] * dim
    high = [room[i] - r for i in range(dim)]
    axes = range(dim)

    def substep():
        for i in axes:
            v[i] += g[i] * h
        touched = []
        for i in axes:
            p[i] += v[i] * h
            if p[i] < low[i]:
                p[i] = low[i]
                if v[i] < 0:
                    touched.append(i)
            elif p[i] > high[i]:
                p[i] = high[i]
                if v[i] > 0:
                    touched.append(i)
        if touched:
            for i in axes:
                v[i] *= -alpha if i in touched else beta

    out = sys.stdout
    out.write("t,x,y,z,vx,vy,vz\n" if dim == 3 else "t,x,y,vx,vy\n")
    rows = []
    written = 0

    def row(t):
        values = [t, *p, *v]
        if not all(math.isfinite(x) for x in values):
            fail(f"non-finite state at t = {t!r}")
        rows.append(",".join(map(repr, values)))  # repr: shortest round-trip form

    def flush():
        nonlocal written
        if rows:
            out.write("\n".join(rows) + "\n")
            written += len(rows)
            rows.clear()

    # The document's clock, exactly: the same float additions of dt. The
    # steps alone are timed (perf_counter around them; the rows are not).
    t = 0.0
    step_seconds = 0.0
    clock = time.perf_counter
    row(t)
    while abs(t) < abs(duration):
        started = clock()
        for _ in range(substeps):
            substep()
        step_seconds += clock() - started
        t = t + dt
        row(t)
        if len(rows) >= CHUNK_ROWS:
            flush()
    flush()
    if written != steps + 1:
        fail(f"wrote {written} rows, the protocol expects steps + 1 = {steps + 1}")
    out.write("#end " + json.dumps({"step_seconds": step_seconds}) + "\n")
    out.flush()


def main():
    if "--session" in sys.argv[1:]:
        # Sessions (docs/external.md): one scenario per line, each answered
        # with header, rows and the #end line, until standard input ends.
        for line in sys.stdin:
            if line.strip():
                run(read_scenario(line))
    else:
        run(read_scenario(sys.stdin.read()))


if __name__ == "__main__":
    try:
        main()
    except BrokenPipeError:
        # The harness stopped reading (it ends a run early, e.g. when the ball
        # left the room). Point stdout at /dev/null so that Python's own flush
        # at exit does not raise again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        fail("standard output closed early")
    except (KeyError, TypeError, ValueError) as e:
        fail(f"bad scenario: {e!r}")
