"""New servos all at the factory ID 0, on servo_sim and on both virtual
boards: their answers overlap on the wire and garble each other on every
simulator alike (one rule: firmware/boards/host_sim/sim_bus.h,
tools/vboard/bus.py), as on a real wire. scan finds ID 0 shared, and
`id bringup`, which needs each new servo's serial number whole, asks for
one servo at a time and fails with that reason, on all three."""
import pytest

from servoctl.cli import main
from servoctl.sim import Simulator

# Six servos on servo_sim; two emulated boards (each costs a CPU's worth).
SIMULATORS = [("servo_sim", 6), ("stm32f103", 2), ("stm32f030k6", 2)]


@pytest.mark.parametrize("board,count", SIMULATORS)
def test_new_servos_at_one_id_collide_alike_on_every_simulator(tmp_path, capsys, board, count):
    sim = Simulator(ids=[0] * count, state_dir=str(tmp_path / "state"),
                    board=None if board == "servo_sim" else board, fast=True).start()
    try:
        def run(*args):
            rc = main(["--port", sim.url, *args], clock=sim.clock_s)
            out = capsys.readouterr()
            return rc, out.out, out.err

        rc, out, err = run("scan", "--last", "2")
        assert rc == 1, out + err
        assert "servo 0 at 115200 baud: TWO OR MORE SERVOS hold this ID" in out and "garbled" in out, out
        assert "IDs held by two or more servos: 0" in err
        rc, out, err = run("id", "bringup", "--first", "1", "--count", str(count), "--wait-s", "3")
        assert rc == 3 and "connect one new servo at a time" in out, out + err
        # Said once while the collisions go on, not at every probe (a probe a second). An
        # emulated board slowed by a loaded PC may miss the first probe (no answer in time):
        # the prompt for a new servo comes once, before the collisions.
        assert out.count("their answers collide") == 1, out
        assert out.count("connect new servo") <= 1 and out.find("connect new servo") < out.find("collide"), out
        assert ("no servo alone at ID 0 within 3 s (two or more answer there at once, and their "
                "answers collide: connect one new servo at a time); 0 numbered") in err, err
        assert "host rate" not in err, err  # they answered, garbled: not a rate to blame
        assert sim.state(0)["garbled"] > 0
    finally:
        sim.stop()


def test_the_wires_overlap_rule():
    """hal/ports/host/wire_overlap.c, which both simulators use: a receiver
    samples the wired AND in the middle of the first byte's bits; a driver
    in step with another is taken as a bit behind it."""
    from vboard.native import wire_overlap

    byte_s = 10 / 115200
    assert wire_overlap(0xFF, 0xFF, 0.0, byte_s) == 0xFE  # the later start bit at data bit 0
    assert wire_overlap(0x55, 0x00, 9 * byte_s / 10, byte_s) == 0x55  # only the stop bit overlaps
    assert wire_overlap(0x55, 0xFF, 3 * byte_s / 10, byte_s) == 0x55 & 0b11111011
    assert wire_overlap(0xFF, 0x00, -byte_s / 10, byte_s) == 0x80  # a bit ahead: its stop bit last
