"""servoctl calibrate on the simulator, built the way a servo may come: the
encoder's magnet turned 30 degrees, the motor's leads swapped, the current
amplifier reading 25 counts at no current (control port: magnet, swapleads,
ampzero). Calibrate finds each and stores it (items 91, 82's sign, 90);
then moves land, the current reads 0 at rest, and after a power-up the
calibrated zero reads 0. Time is the simulator's (sim.sleep)."""
from servoctl.calibrate import calibrate
from servoctl.cli import main
from servoctl.servo import Servo
from servoctl.sim import Simulator

from .conftest import finish

AMP_ZERO = 25


def start(tmp_path, *controls):
    sim = Simulator(fast=True, state_dir=str(tmp_path / "state")).start()
    for line in controls:
        assert sim.control(line).strip() == "ok", line
    return sim


def test_calibrate_finds_how_the_servo_is_built(tmp_path):
    sim = start(tmp_path, "magnet 30", "swapleads 1", f"ampzero {AMP_ZERO}")
    try:
        with sim.bus(timeout=0.2) as bus:
            s = Servo(bus, 1)
            sim.sleep(0.1)
            assert s.read("current") > 0  # the amplifier's offset reads as current
            start_count = s.read("encoder_count")
            c = calibrate(s, sim.sleep)
            assert c.current_zero == AMP_ZERO and c.reversed and c.gear_ratio == -345, c
            assert abs(c.encoder_zero - start_count) <= 4, (c, start_count)  # back where it began
            assert (s.read("current_zero"), s.read("gear_ratio"), s.read("encoder_zero")) == \
                (AMP_ZERO, -345, c.encoder_zero)
            assert s.read("current") == 0 and abs(s.read_motion().angle_decideg) <= 1
            s.write("soft_start_on", 0)
            for target in (450, -300):
                s.move(target, interval_ms=500)
                sim.sleep(1.5)
                assert abs(s.read_motion().angle_decideg - target) <= 5, target
            s.move(0, interval_ms=500)
            sim.sleep(1.5)
            s.stop("release")
        assert sim.control("powercycle").strip() == "ok"
        sim.sleep(0.5)
        with sim.bus(timeout=0.2) as bus:
            s = Servo(bus, 1)
            assert abs(s.read_motion().angle_decideg) <= 3  # the calibrated zero, from power-up
            assert s.read("current") == 0
    finally:
        finish(sim, [1])


def test_a_servo_built_as_the_reference_keeps_its_items(tmp_path, capsys):
    """The CLI on the reference as built, keeping its zero: the current's
    zero 0, the direction as wired, item 90 untouched."""
    sim = start(tmp_path)
    try:
        assert main(["--port", sim.url, "calibrate", "1", "--keep-zero"], clock=sim.clock_s) == 0
        out = capsys.readouterr().out
        assert "0 ADC counts" in out and "as wired (gear_ratio 345)" in out and "zero                      kept" in out, out
        with sim.bus(timeout=0.2) as bus:
            s = Servo(bus, 1)
            assert (s.read("current_zero"), s.read("gear_ratio"), s.read("encoder_zero")) == (0, 345, 0)
    finally:
        finish(sim, [1])
