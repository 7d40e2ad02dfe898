#!/usr/bin/env python3
"""Checks that two bouncecheck stress or sweep result folders are the same run
apart from timings: A_DIR/stress.json and stress.csv against B_DIR's (or
sweep.json and sweep.csv), e.g. a merged sharded run against an unsharded one.

    same_apart_from_timings.py A_DIR B_DIR

Left out of the comparison, because they measure this run's wall clock or
machine, not its result:
  JSON  provenance.machine (date, command line, cores), top-level wall_seconds,
        parameters.out and parameters.jobs (where and how widely each ran);
        stress results[*]: run_seconds, invariants.time_budget.{worst,first_value},
        invariants.flat_cost.{worst,first_value} (both are wall-time measures);
        sweep rows[*]: ns_per_step, sec_per_sim_sec, min_seconds and pareto
        (the front is drawn against sec_per_sim_sec).
  CSV   stress.csv: run_seconds and cost_ratio, and first_value on a row whose
        first broken invariant is time_budget or flat_cost;
        sweep.csv: ns_per_step and sec_per_sim_sec.
Everything else must be equal: JSON numbers as written (text, not the parsed
double), keys in the same order; CSV fields byte for byte. sweep.html holds the
timings inline; it only has to exist in both. A stress run's stress-scenarios/
(a file per generated scenario that broke something) must hold the same files
with the same bytes. Prints the first difference and
exits 1; exits 0 when the two agree, 2 on a usage problem.
"""
import csv
import json
import os
import sys

STRESS_CSV_TIMINGS = {"run_seconds", "cost_ratio"}
SWEEP_CSV_TIMINGS = {"ns_per_step", "sec_per_sim_sec"}
WALL_CLOCK_INVARIANTS = ("time_budget", "flat_cost")


class Different(Exception):
    pass


class Number(str):
    """A JSON number kept as its text, so 0.1 and 0.10000000000000001 differ."""


def load_json(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f, parse_float=Number, parse_int=Number)


def drop(obj, *keys):
    # Missing keys are fine: the same drop runs on both sides.
    for key in keys:
        if isinstance(obj, dict):
            obj.pop(key, None)


def strip_json(doc, kind):
    drop(doc, "wall_seconds")
    drop(doc.get("provenance"), "machine")
    drop(doc.get("parameters"), "out", "jobs")
    if kind == "stress":
        for result in doc.get("results", []):
            drop(result, "run_seconds")
            invariants = result.get("invariants", {})
            for name in WALL_CLOCK_INVARIANTS:
                drop(invariants.get(name), "worst", "first_value")
    else:
        for row in doc.get("rows", []):
            drop(row, "ns_per_step", "sec_per_sim_sec", "min_seconds", "pareto")
    return doc


def show(value):
    return str(value) if isinstance(value, Number) else json.dumps(value)


def compare_json(a, b, where):
    if type(a) is not type(b):
        raise Different(f"{where}: {show(a)} != {show(b)}")
    if isinstance(a, dict):
        if list(a) != list(b):
            only_a = [k for k in a if k not in b]
            only_b = [k for k in b if k not in a]
            detail = f"only in A {only_a}, only in B {only_b}" if only_a or only_b else "keys in another order"
            raise Different(f"{where}: {detail}")
        for key in a:
            compare_json(a[key], b[key], f"{where}.{key}")
    elif isinstance(a, list):
        for i, (x, y) in enumerate(zip(a, b)):
            compare_json(x, y, f"{where}[{i}]")
        if len(a) != len(b):
            raise Different(f"{where}: {len(a)} elements != {len(b)}")
    elif a != b:
        raise Different(f"{where}: {show(a)} != {show(b)}")


def read_csv(path, timings):
    with open(path, encoding="utf-8", newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise Different(f"{path}: empty")
    header = rows[0]
    kept = [i for i, name in enumerate(header) if name not in timings]
    first_broken = header.index("first_broken") if "first_broken" in header else None
    first_value = header.index("first_value") if "first_value" in header else None
    out = []
    for row in rows:
        row = list(row)
        # A wall-clock invariant's value when it broke is a timing too.
        if (row is not rows[0] and first_broken is not None and first_value is not None
                and len(row) > max(first_broken, first_value) and row[first_broken] in WALL_CLOCK_INVARIANTS):
            row[first_value] = "(timing)"
        out.append([(header[i] if i < len(header) else str(i), row[i]) for i in kept if i < len(row)]
                   + [("(extra field)", v) for v in row[len(header):]])
    return out


def compare_csv(path_a, path_b, timings):
    a, b = read_csv(path_a, timings), read_csv(path_b, timings)
    name = os.path.basename(path_a)
    for line, (row_a, row_b) in enumerate(zip(a, b), start=1):
        if len(row_a) != len(row_b):
            raise Different(f"{name} line {line}: {len(row_a)} fields != {len(row_b)}")
        for (column, x), (_, y) in zip(row_a, row_b):
            if x != y:
                raise Different(f"{name} line {line}, column {column}: {x!r} != {y!r}")
    if len(a) != len(b):
        raise Different(f"{name}: {len(a)} lines != {len(b)}")


def compare_files(dir_a, dir_b, sub):
    """The files under sub/ (a stress run's reproducible scenario files), byte for byte."""
    def listing(d):
        root = os.path.join(d, sub)
        return sorted(os.listdir(root)) if os.path.isdir(root) else []
    names_a, names_b = listing(dir_a), listing(dir_b)
    if names_a != names_b:
        only_a = [n for n in names_a if n not in names_b]
        only_b = [n for n in names_b if n not in names_a]
        raise Different(f"{sub}/: only in A {only_a}, only in B {only_b}")
    for name in names_a:
        with open(os.path.join(dir_a, sub, name), "rb") as fa, open(os.path.join(dir_b, sub, name), "rb") as fb:
            if fa.read() != fb.read():
                raise Different(f"{sub}/{name} differs")


def main(argv):
    if len(argv) != 3:
        print("usage: same_apart_from_timings.py A_DIR B_DIR", file=sys.stderr)
        return 2
    dir_a, dir_b = argv[1], argv[2]
    kinds = [k for k in ("stress", "sweep") if os.path.exists(os.path.join(dir_a, k + ".json"))]
    if len(kinds) != 1:
        print(f"{dir_a}: expected exactly one of stress.json or sweep.json", file=sys.stderr)
        return 2
    kind = kinds[0]
    needed = [kind + ".json", kind + ".csv"] + (["sweep.html"] if kind == "sweep" else [])
    try:
        for name in needed:
            for d in (dir_a, dir_b):
                if not os.path.isfile(os.path.join(d, name)):
                    raise Different(f"{os.path.join(d, name)} is missing")
        a = strip_json(load_json(os.path.join(dir_a, kind + ".json")), kind)
        b = strip_json(load_json(os.path.join(dir_b, kind + ".json")), kind)
        compare_json(a, b, kind + ".json")
        timings = STRESS_CSV_TIMINGS if kind == "stress" else SWEEP_CSV_TIMINGS
        compare_csv(os.path.join(dir_a, kind + ".csv"), os.path.join(dir_b, kind + ".csv"), timings)
        if kind == "stress":
            compare_files(dir_a, dir_b, "stress-scenarios")
    except Different as e:
        print(f"differ: {e}\n  A = {dir_a}\n  B = {dir_b}")
        return 1
    print(f"same apart from timings: {kind}.json, {kind}.csv in {dir_a} and {dir_b}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
