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
from .joint import narrowed_at_rest

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


def test_a_joints_limits_refuse_bring_up_and_move_with_a_new_zero(tmp_path, capsys):
    """A servo whose angle limits are narrowed (-10..10 deg: a joint's) is
    in a joint: calibrate, identify and tune refuse to turn it past them,
    nothing moved, unless told the horn is free. Calibrate then kept the
    limits as numbers while moving the zero 8 deg: the joint's safe range
    moved 8 deg on the real horn. Now the limits move with the zero."""
    sim = start(tmp_path)
    try:
        zero_at = narrowed_at_rest(sim, 1, 100, 80)  # about 80: the zero goes here
        horn_deg = sim.state(1)["angle"]
        for command in ("calibrate", "identify", "tune"):
            assert main(["--port", sim.url, command, "1"], clock=sim.clock_s) == 2, command
            err = capsys.readouterr().err
            assert "angle limits are on at -10.0..10.0 deg" in err and "--past-limits" in err, err
        assert abs(sim.state(1)["angle"] - horn_deg) < 0.05  # nothing moved
        assert main(["--port", sim.url, "calibrate", "1", "--past-limits"], clock=sim.clock_s) == 0
        out = capsys.readouterr().out
        low, high = -100 - zero_at, 100 - zero_at
        assert f"-10.0..10.0 deg from the old zero are {low / 10:.1f}..{high / 10:.1f} from the new" in out, out
        with sim.bus(timeout=0.2) as bus:
            s = Servo(bus, 1)
            assert (s.read("angle_min"), s.read("angle_max")) == (low, high)
            s.move(high, interval_ms=300)  # the joint's old 10 deg
            sim.sleep(0.6)
            assert abs(sim.state(1)["angle"] - (horn_deg + (100 - zero_at) / 10)) < 0.5  # the same horn position
    finally:
        finish(sim, [1])
