"""How deep the application's stack has been, against the build's static
figure (docs/footprint.md, "The stack"):

    python -m vboard.stack_depth [--markdown]    (from tools/)

Each board runs its shipped image through every kind of work a host can
give it: each motion packet, DriveDuty, a stream of setpoints with Sync
Monitor rounds, a sync move, reads of every item and of ReadMotion,
ReadStore and ReadFaults, a config write (flash). (A fault handler's own
frame is not seen: the reset after it starts the measure again.) Then item 74 (the bytes of stack the firmware found never written since
start, a word a control tick) gives the deepest it has been, and
cmake/stack-report.py's line the static worst case of the same image."""
import argparse
import math
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from servoctl import group
from servoctl.registers import ITEMS
from servoctl.servo import Servo
from servoctl.sim import Simulator
from servoctl.stream import stream_file

from .board import PARTS, elf
from .idle_skip import _elf, _symbol

REPO = Path(__file__).resolve().parents[2]
BOARDS = ("stm32f103", "stm32f030k6", "stm32g031k8")  # docs/footprint.md's rows, in its order


def static_worst(board: str) -> tuple:
    """(worst case, reserved) in bytes, as cmake/stack-report.py says."""
    out = subprocess.run([sys.executable, str(REPO / "cmake/stack-report.py"), str(elf(board)),
                          str(REPO / "build" / PARTS[board].build)], capture_output=True, text=True, check=True).stdout
    worst, reserved = re.search(r"worst case (\d+) B of (\d+) B reserved", out).groups()
    return int(worst), int(reserved)


def reserved_bytes(board: str) -> int:
    """The stack itself, without its section's alignment."""
    return _symbol(_elf(elf(board)), "STACK_SIZE")[0]


def work(sim, servo) -> None:
    bus = servo.bus
    servo.write("soft_start_on", 0)
    for item in ITEMS:
        if item.public:
            servo.read(item.name)
    servo.read_all()
    servo.read_motion()
    servo.read_store()
    servo.read_fault(0)
    servo.move(450, interval_ms=300)
    sim.sleep(0.4)
    servo.move(-300, velocity=1500, acc_ms=50, dec_ms=50)
    sim.sleep(0.6)
    servo.wheel("run", 90)
    sim.sleep(0.3)
    servo.stop("hold")
    servo.move(3600, interval_ms=800, multi_turn=True)
    sim.sleep(0.9)
    servo.move(0, interval_ms=800, multi_turn=True)
    sim.sleep(0.9)
    servo.drive_duty(0.2, 100)
    sim.sleep(0.2)
    group.sync_move(bus, {1: 10.0}, 0.3)
    sim.sleep(0.4)
    times = [i * 0.02 for i in range(50)]
    stream_file(bus, times, {1: [10.0 + 20.0 * math.sin(t * 6.0) for t in times]})
    servo.write("angle_max", 1700)  # a config save: flash
    sim.sleep(0.8)  # a sweep of the scan: a word a tick


def measure(board: str) -> dict:
    with tempfile.TemporaryDirectory() as state:
        sim = Simulator(ids=(1,), tcp=True, state_dir=state, board=board, fast=True).start()
        try:
            with sim.bus(timeout=0.3) as bus:
                servo = Servo(bus, 1)
                work(sim, servo)
                unused = servo.read("stack_unused")
        finally:
            sim.stop()
    worst, _ = static_worst(board)
    reserved = reserved_bytes(board)
    return {"board": board, "reserved": reserved, "static": worst, "deepest": reserved - unused, "unused": unused}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--markdown", action="store_true", help="the table as docs/footprint.md has it")
    args = ap.parse_args(argv)
    rows = [measure(b) for b in BOARDS]
    print("| board | stack reserved | static worst case (stack-report.py) | deepest measured (item 74) |")
    print("|---|---|---|---|")
    for r in rows:
        print(f"| {r['board']} | {r['reserved']} B | {r['static']} B | {r['deepest']} B |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
