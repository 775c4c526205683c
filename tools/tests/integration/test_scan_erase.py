"""`servoctl scan` finds a servo that is in a page erase when the sweep
begins (docs/decisions-hardware.md): a sweep asks each ID once, so it
first ends the bus's quiet and waits the erase out (scan.wake). Time is
the simulator's."""
import rich.progress  # noqa: F401  loaded before the sweep: its import takes longer than an erase

from servoctl.cli.args import build_parser
from servoctl.cli.cmd_bus import cmd_scan
from servoctl.servo import Servo
from servoctl.sim import Simulator

SLOTS = 21  # config records in a page


def test_a_scan_into_an_erase_finds_the_servo(tmp_path, capsys):
    sim = Simulator(fast=True, ids=[1], state_dir=str(tmp_path / "state")).start()
    try:
        with sim.bus(timeout=0.2) as bus:
            s = Servo(bus, 1)
            n = 0
            while True:  # changes until one starts the other page: erased after 0.1 s of quiet
                n += 1
                s.write("current_limit", 3000 + n % 2)
                records = s.read_store().records
                if records % SLOTS == 1 and records > 1:
                    break
            stalled = sim.state(1)["flash_stall_ms"]
            sim.sleep(bus.arrived_at + 0.105 - sim.clock_s())  # the sweep begins in the erase
            rc = cmd_scan(bus, build_parser().parse_args(["scan", "--last", "3"]))
            out = capsys.readouterr().out
            sim.sleep(0.1)
            assert sim.state(1)["flash_stall_ms"] - stalled >= 40.0, "no erase ran: the test proves nothing"
            assert rc == 0 and "1 servo(s) found" in out, out
    finally:
        sim.stop()
