#!/usr/bin/env python3
"""An independent solution of bouncecheck's damping law for the exact tests.

Event-driven in 100-digit arithmetic (mpmath, Debian's python3-mpmath),
written apart from exact/exact_model.cpp and sharing no code with it: every
flight is the parabola p + v t + g t^2 / 2, every contact the law (normal
velocity times -alpha, every other component times beta). It makes no
Zeno approximation until the axes that gravity presses into a wall (all of
them, or two or more while every other has a time scale of 1e-6 s or more)
have time
scales sqrt(2 E_i) / |g_i| below 1e-40 s (E_i = v_i^2 / 2 + |g_i| d_i),
then rests the ball on those walls (every velocity 0 for beta < 1): 28 orders
of magnitude below exact's own lock. The vertical axis's lock is the
accumulation time printed.

    event_driven.py SCENARIO.toml > SAMPLES.csv

prints the state at the document clock's sample times (t_0 = 0,
t_{n+1} = t_n + dt in binary64, as the harness steps it), in the
--trajectories CSV format with 17 significant digits, and the accumulation
time and contact count as # comments.
"""
import sys
import tomllib

import mpmath as mp

mp.mp.dps = 100
LOCK_TIME = mp.mpf("1e-40")
FAR_TIME = mp.mpf("1e-6")


def main(path):
    with open(path, "rb") as f:
        sc = tomllib.load(f)
    room = sc["room"]["size"]
    dim = len(room)
    r = mp.mpf(sc["ball"]["radius"])
    p = [mp.mpf(x) for x in sc["ball"]["position"]]
    v = [mp.mpf(x) for x in sc["ball"]["velocity"]]
    g = [mp.mpf(x) for x in sc["world"]["gravity"]]
    alpha = mp.mpf(sc["damping"]["normal"])
    beta = mp.mpf(sc["damping"]["tangential"])
    dt = float(sc["run"]["dt"])
    duration = float(sc["run"]["duration"])
    # The centre's range computed in binary64 as the loader does, so that a
    # start the harness sees touching a wall is touching here too.
    lo = [r] * dim
    hi = [mp.mpf(room[i] - sc["ball"]["radius"]) for i in range(dim)]

    # The document clock, in binary64 like simulators/document_clock.h.
    times = [0.0]
    while abs(times[-1]) < abs(duration):
        times.append(times[-1] + dt)

    def time_to_wall(d, u, a):
        # d >= 0 from the wall, u speed towards it, a acceleration towards it.
        if d <= 0:
            if u > 0:
                return mp.mpf(0)
            if u < 0 and a > 0:
                return -2 * u / a
            return mp.inf
        if a == 0:
            return d / u if u > 0 else mp.inf
        disc = u * u + 2 * a * d
        if disc <= 0:
            return mp.inf
        roots = [(-u + s * mp.sqrt(disc)) / a for s in (1, -1)]
        positive = [x for x in roots if x > 0]
        return min(positive) if positive else mp.inf

    locked = [False] * dim
    t = mp.mpf(0)
    contacts = 0
    rest = None
    out = []
    k = 0

    # Samples before t_end; one at a contact instant shows the velocity after
    # the contact, as exact's does.
    def emit_until(t_end):
        nonlocal k
        while k < len(times) and mp.mpf(times[k]) < t_end:
            tau = mp.mpf(times[k]) - t
            ps = [p[i] + v[i] * tau + g[i] * tau * tau / 2 if not locked[i] else p[i] for i in range(dim)]
            vs = [v[i] + g[i] * tau if not locked[i] else v[i] for i in range(dim)]
            out.append((times[k], ps, vs))
            k += 1

    while k < len(times):
        pressed = [i for i in range(dim) if not locked[i] and g[i] != 0]
        if pressed:
            def scale(i):
                d = p[i] - lo[i] if g[i] < 0 else hi[i] - p[i]
                return mp.sqrt(v[i] * v[i] + 2 * abs(g[i]) * d) / abs(g[i])
            tiny = [i for i in pressed if scale(i) < LOCK_TIME]
            far = [i for i in pressed if scale(i) >= FAR_TIME]
            if tiny and (len(tiny) == len(pressed) or (len(tiny) >= 2 and len(tiny) + len(far) == len(pressed))):
                for i in tiny:
                    p[i] = lo[i] if g[i] < 0 else hi[i]
                    locked[i] = True
                    v[i] = mp.mpf(0)
                if beta < 1:
                    v = [mp.mpf(0)] * dim
                g = [mp.mpf(0) if locked[i] else g[i] for i in range(dim)]
                if dim - 1 in tiny:
                    rest = t
        candidates = []
        for i in range(dim):
            if locked[i]:
                continue
            candidates.append((time_to_wall(p[i] - lo[i], -v[i], -g[i]), i, -1))
            candidates.append((time_to_wall(hi[i] - p[i], v[i], g[i]), i, +1))
        tau = min(c[0] for c in candidates) if candidates else mp.inf
        emit_until(t + tau if tau != mp.inf else mp.inf)
        if tau == mp.inf:
            break
        for i in range(dim):
            if not locked[i]:
                p[i] += v[i] * tau + g[i] * tau * tau / 2
                v[i] += g[i] * tau
        t += tau
        # Walls reached at the same instant (a start in a corner) all apply.
        for when, axis, side in candidates:
            if when != tau:
                continue
            p[axis] = lo[axis] if side < 0 else hi[axis]
            for j in range(dim):
                v[j] *= -alpha if j == axis else beta
            contacts += 1

    axes = "xyz"[:dim]
    print("# independent event-driven solution, tests/data/exact_corner/event_driven.py")
    print(f"# accumulation {mp.nstr(rest, 20) if rest is not None else 'none'}, contacts {contacts}")
    print("t," + ",".join(axes) + "," + ",".join("v" + a for a in axes))
    for time, ps, vs in out:
        print(repr(time) + "," + ",".join(mp.nstr(x, 17, strip_zeros=False) for x in ps + vs))


if __name__ == "__main__":
    main(sys.argv[1])
