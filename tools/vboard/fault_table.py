"""The servo's own faults, each injected into the shipped image on each
virtual board (inject.py), and what the firmware does: the table of
docs/safety.md, "The servo's own faults":

    python -m vboard.fault_table [--markdown]    (from tools/)

For each fault: the exception taken, the time from the faulting
instruction to the store that turned the bridge's outputs off (or, for a
hang and a brown-out, to the reset that let them go), the reset that
followed, and what the next start-up read from the record kept across it
(ports/stm32_common/kept_ram.h): the fault history's kind, the exception,
the function of the faulting PC. Every time is the boards' simulated time,
from their cycle models (docs/virtual-boards.md), so the table is the same
on any machine."""
import argparse
import struct
import sys
import tempfile

from servoctl.fault_code import FaultCode
from servoctl.fault_symbols import Symbols

from .bench import runner_for
from .board import PARTS, elf
from .idle_skip import _elf, _symbol

BOARDS = ("stm32f103", "stm32f030k6", "stm32g031k8")  # docs/safety.md's rows, in its order
KINDS = ("bus", "undef", "stack", "hang", "brownout")
WHAT = {"bus": "bus error on a register read", "undef": "undefined instruction",
        "stack": "stack overflow", "hang": "main loop hung", "brownout": "supply dip (5 ms)"}
HISTORY = {10: "firmware_fault", 11: "watchdog_reset", 12: "software_reset", 13: "brown_out"}


def _run(runner, seconds, until):
    end = runner.now_s + seconds
    while runner.now_s < end:
        runner.step()
        if until():
            return True
    return False


def _kept(board, symbols):
    raw = bytes(board.core.uc.mem_read(_symbol(_elf(board.injector_elf), "_kept_ram")[0], 36))
    kind = raw[4]
    if kind != 10:
        return HISTORY.get(kind, f"kind {kind}")
    code = FaultCode(*struct.unpack_from("<IIHHBB", raw, 12))
    where = (symbols.name(code.pc) or f"{code.pc:#010x}").split("+")[0] if code.frame_valid else "(no frame)"
    bits = " ".join(code.status_bits)
    return f"firmware_fault: {code.exception_name} in {where}" + (f" [{bits}]" if bits else "")


def measure(board_name: str, kind: str) -> dict:
    with tempfile.TemporaryDirectory() as state:
        runner = runner_for(board_name, [1], state)
        try:
            board = runner.boards[0]
            core = board.core
            _run(runner, 0.3, lambda: False)  # the bootloader's window, then the application
            resets = dict(board.resets)
            command = f"brownout 1 5" if kind == "brownout" else f"inject 1 {kind}"
            at_s = core.time_s
            assert runner.command(command) == "ok", command
            if not _run(runner, 1.0, lambda: board.resets != resets):
                raise RuntimeError(f"{board_name}: no reset after {command}")
            reset = next(k for k in board.resets if board.resets[k] != resets[k])
            inj = board.injector
            if kind == "hang":
                off_us = (board.last_reset_s - inj.hung_at_s) * 1e6
            elif kind == "brownout":
                off_us = (board.last_reset_s - at_s) * 1e6 - 5000  # the dip ends in the reset; VDD off at once
            elif core.fault_at_s is None:  # the M0's overflow: no exception; its check turns the bridge off, then resets
                off_us = (board.last_reset_s - inj.overflow_at_s) * 1e6
            else:
                off_us = (inj.bridge_off_at_s - core.fault_at_s) * 1e6
            taken = ",".join(str(e) for e in sorted(core.taken) if 2 <= e < 15 or e == 0) or "-"
            _run(runner, 0.6, lambda: board.in_application() and runner.now_s > board.last_reset_s + 0.3)
            return {"board": board_name, "fault": WHAT[kind], "exception": taken, "bridge_off_us": off_us,
                    "reset": reset, "history": _kept(board, Symbols(elf(board_name)))}
        finally:
            runner.bus.close()
            runner.control.close()
            runner.clock.close()


def table(rows) -> str:
    out = ["| board | fault | exception taken | to the bridge off | reset | the fault history then shows |",
           "|---|---|---|---|---|---|"]
    for r in rows:
        off = r["bridge_off_us"]
        shown = ("at once (held in reset)" if r["reset"] == "power" else
                 f"{off:.2f} µs" if off < 100 else f"{off / 1000:.2f} ms")
        if r["exception"] == "-" and r["reset"] == "software":
            shown = f"{shown}: the stack's check found it, then the reset"
        out.append(f"| {r['board']} | {r['fault']} | {r['exception']} | {shown} | {r['reset']} | {r['history']} |")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--markdown", action="store_true", help="the table as docs/safety.md has it")
    ap.add_argument("--board", choices=sorted(PARTS), action="append", help="one board (default all three)")
    args = ap.parse_args(argv)
    rows = []
    for board_name in args.board or BOARDS:
        for kind in KINDS:
            rows.append(measure(board_name, kind))
            if not args.markdown:
                print(rows[-1], file=sys.stderr)
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
