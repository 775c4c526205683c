#!/usr/bin/env python3
"""STOP ALL's time to the stopped servo in `servoctl ui`, on the
simulator's clock, for each thing the bus thread may be busy with, with 1
and with 11 silent servos on the bus (tools/tests/ui_stop_bench.py says
how it is measured). Prints docs/ui.md's table; exit 1 if a case is over
50 ms or was not under way when STOP ALL came.

    .venv/bin/python scripts/ui_stop_bench.py   (after the host build)"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

from tests.ui_stop_bench import LIMIT_MS, SITUATIONS, measure  # noqa: E402

SILENT = (1, 11)


def main() -> int:
    rows = {n: {} for n in SITUATIONS}
    for silent in SILENT:
        for r in measure(silent):
            rows[r["situation"]][silent] = r
    print("| STOP ALL during | " + " | ".join(f"{s} silent servo{'s' * (s > 1)}" for s in SILENT) + " |")
    print("|---|" + "---:|" * len(SILENT))
    bad = []
    for name, by_silent in rows.items():
        cells = []
        for silent in SILENT:
            r = by_silent[silent]
            note = "" if r["under_way"] in (True, None) else " (had ended before it)"
            cells.append(f"{r['ms']:.1f} ms{note}")
            if r["ms"] > LIMIT_MS or r["under_way"] is False:
                bad.append(f"{name}, {silent} silent: {r['ms']:.1f} ms{note}")
        print(f"| {name} | " + " | ".join(cells) + " |")
    for b in bad:
        print(f"ui_stop_bench: over {LIMIT_MS:.0f} ms or not under way: {b}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
