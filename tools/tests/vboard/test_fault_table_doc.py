"""docs/safety.md's table of the servo's own faults is what
`python -m vboard.fault_table --markdown` prints now (simulated time, so
the same on any machine), and every fault in it turned the bridge off
within what the firmware keeps: 5 us on the F103, 10 us on the F030 and
the G031 from the faulting instruction (the ARMv6-M boards' stack guard, a
check, within a tick). Its rows are every board's: fault_table.BOARDS."""
from pathlib import Path

from vboard import fault_table

from .test_virtual_boards import BOARDS

DOC = Path(__file__).resolve().parents[3] / "docs" / "safety.md"
LIMIT_US = {"stm32f103": 5.0, "stm32f030k6": 10.0, "stm32g031k8": 10.0}


def test_the_docs_table_is_the_commands():
    assert tuple(LIMIT_US) == fault_table.BOARDS and set(BOARDS) == set(fault_table.BOARDS), "a board the table leaves out"
    rows = [fault_table.measure(board, kind) for board in fault_table.BOARDS for kind in fault_table.KINDS]
    for r in rows:
        if r["reset"] == "software" and r["exception"] != "-":  # a fault handler's own store
            assert 0 < r["bridge_off_us"] <= LIMIT_US[r["board"]], r
        elif r["reset"] == "software":  # the M0's stack guard, checked each control tick
            assert 0 < r["bridge_off_us"] <= 1000.0, r
        assert r["history"] != "kind 0", r  # every one of them is in the history
    assert fault_table.table(rows) in DOC.read_text(), "docs/safety.md: rerun python -m vboard.fault_table --markdown"
