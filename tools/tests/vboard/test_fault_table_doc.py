"""docs/safety.md's table of the servo's own faults is what
`python -m vboard.fault_table --markdown` prints now (simulated time, so
the same on any machine), and every fault in it turned the bridge off
within what the firmware keeps: 5 us on the F103, 10 us on the F030 from
the faulting instruction (the M0's stack guard, a check, within a tick)."""
from pathlib import Path

from vboard import fault_table

DOC = Path(__file__).resolve().parents[3] / "docs" / "safety.md"
LIMIT_US = {"stm32f103": 5.0, "stm32f030k6": 10.0}


def test_the_docs_table_is_the_commands():
    rows = [fault_table.measure(board, kind) for board in LIMIT_US for kind in fault_table.KINDS]
    for r in rows:
        if r["reset"] == "software" and r["exception"] != "-":  # a fault handler's own store
            assert 0 < r["bridge_off_us"] <= LIMIT_US[r["board"]], r
        elif r["reset"] == "software":  # the M0's stack guard, checked each control tick
            assert 0 < r["bridge_off_us"] <= 1000.0, r
        assert r["history"] != "kind 0", r  # every one of them is in the history
    assert fault_table.table(rows) in DOC.read_text(), "docs/safety.md: rerun python -m vboard.fault_table --markdown"
