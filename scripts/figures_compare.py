#!/usr/bin/env python3
"""Compares the figures two recorded pytest runs judged (tools/tests/
figure_record.py): every assertion's compared values and every test's
printed figures, test by test, and names each one that moved.

    figures_compare.py BASE OTHER [--again BASE2] [--show N]

BASE and OTHER are SERVO_FIGURES folders (scripts/other_kernels.sh makes
them). With --again, a second run like BASE: a figure that moves between
BASE and BASE2 moves from run to run (the host's time, a port, a process),
and is listed apart from those that move only with the kernel. Exit 1 when
a test's outcome differs between BASE and OTHER."""
import argparse
import json
import math
import pathlib
import re
import sys
from collections import defaultdict

NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?|[-+]?inf\b|\bnan\b")
# Tokens whose digits are no figure: paths, addresses, hashes, pytest's
# temporary folders and xdist workers.
NOISE = re.compile(r"\S*/\S*|0x[0-9a-fA-F]+|\b[0-9a-f]{8,}\b|\bgw\d+\b|pytest-\d+|<[^<>]* at [^<>]*>")


def figures(text: str) -> list:
    return [float(n) for n in NUMBER.findall(NOISE.sub(" ", text))]


def load(folder: str) -> dict:
    """{test: {"outcome": ..., "failure": ..., "stdout": ..., "asserts": {(line, text): [explanation, ...]}}}"""
    tests = defaultdict(lambda: {"outcome": None, "failure": "", "stdout": "", "asserts": defaultdict(list)})
    files = sorted(pathlib.Path(folder).glob("figures-*.jsonl"))
    if not files:
        sys.exit(f"figures_compare: {folder} holds no figures-*.jsonl (was the run made with tests.figure_record?)")
    for path in files:
        for line in path.read_text(encoding="utf-8").splitlines():
            r = json.loads(line)
            t = tests[r["test"]]
            if "assert" in r:
                t["asserts"][(r["line"], r["assert"])].append(r["explanation"])
            elif r["outcome"] != "passed" or t["outcome"] is None:
                t.update(outcome=r["outcome"], failure=r["failure"], stdout=t["stdout"] + r["stdout"])
            else:
                t["stdout"] += r["stdout"]
    return tests


def moved(a: list, b: list):
    """The largest relative change between two lists of figures (inf where
    they differ in number), or None where they are the same."""
    if a == b:
        return None
    if len(a) != len(b):
        return math.inf
    worst = 0.0
    for x, y in zip(a, b):
        if x == y or (math.isnan(x) and math.isnan(y)):
            continue
        scale = max(abs(x), abs(y))
        worst = max(worst, abs(x - y) / scale if scale and math.isfinite(scale) else math.inf)
    return worst


def places(tests: dict) -> dict:
    """{(test, where): figures} for every assertion and every test's print."""
    out = {}
    for name, t in tests.items():
        for (line, text), expls in t["asserts"].items():
            out[(name, f"line {line}: assert {text}")] = [f for e in expls for f in figures(e)]
        out[(name, "printed")] = figures(t["stdout"])
    return out


def shown(figs: list, n: int) -> str:
    text = ", ".join(f"{f:.6g}" for f in figs[:n])
    return text + (f", ... ({len(figs)} figures)" if len(figs) > n else "")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("base")
    ap.add_argument("other")
    ap.add_argument("--again", help="a second run like BASE: what moves between the two is run-to-run")
    ap.add_argument("--show", type=int, default=6, help="figures shown a row (default 6)")
    args = ap.parse_args()
    base, other = load(args.base), load(args.other)
    again = places(load(args.again)) if args.again else {}

    outcomes = sorted((n, base[n]["outcome"], other[n]["outcome"]) for n in base.keys() & other.keys()
                      if base[n]["outcome"] != other[n]["outcome"])
    only = sorted(base.keys() ^ other.keys())
    a, b = places(base), places(other)
    kernel, runs = [], []
    for key in sorted(a.keys() & b.keys()):
        change = moved(a[key], b[key])
        if change is None:
            continue
        row = (key, change, a[key], b[key])
        (runs if key in again and moved(a[key], again[key]) is not None else kernel).append(row)

    print(f"{len(base)} tests in {args.base}, {len(other)} in {args.other}; "
          f"{len(a)} places with figures, {len(kernel) + len(runs)} moved")
    for name, x, y in outcomes:
        print(f"OUTCOME {name}: {x} -> {y}")
        failure = (other if y == "failed" else base)[name]["failure"]
        for line in [l for l in failure.splitlines() if l.startswith("E ")][:4]:
            print("  " + line)
    for name in only:
        print(f"ONLY IN ONE RUN {name}")
    for title, rows in (("moved with the run's kernels (same in BASE and --again)" if args.again
                         else "moved", kernel), ("moved from run to run as well", runs)):
        if not rows:
            continue
        print(f"\n{title}: {len(rows)}")
        for (name, where), change, x, y in sorted(rows, key=lambda r: -r[1]):
            print(f"- {name}\n  {where[:160]}\n  largest relative change {change:.3g}\n"
                  f"  base:  {shown(x, args.show)}\n  other: {shown(y, args.show)}")
    return 1 if outcomes else 0


if __name__ == "__main__":
    sys.exit(main())
