"""Bring-up on the simulator, for each shipped plant,
built as a servo may come (the encoder's magnet turned, the motor's leads
swapped, the current amplifier off zero): from the factory items (the
reference servo's drive train and gains, wrong for the other two),
calibrate, identify, tune and store; then the motion-at-the-limits
figures: a 45 degree move overshoots at most 1 degree and is within 0.5
degree 1.5 s after it began, each way, and a hold is within 0.2 degree 1.5 s
after a load of 0.3 of the stall torque has come, reversed, or gone. Time is
the simulator's (sim.sleep)."""
import tomllib

import pytest

from servoctl.calibrate import calibrate
from servoctl.cli import main
from servoctl.identify import identify
from servoctl.servo import Servo
from servoctl.sim import Simulator
from servoctl.tune import check_step, tune

from ..launchers import PLANTS
from .conftest import finish
from .test_identify import HOST_LINK, PACED, at_the_output, relative_errors

PLANT_FILES = ["reference_st3215.toml", "micro_9g.toml", "class_60kgcm.toml"]
OVERSHOOT_MOST = 10   # decidegrees: 1 degree
SETTLED_MOST = 5      # 0.5 degree
HOLD_MOST = 2         # 0.2 degree
LOAD_SHARE = 0.3      # of the published stall torque


BUILT = ("magnet -40", "swapleads 1", "ampzero 18")  # how these servos came (control port)


def start(tmp_path, file, built=()):
    # Paced, on the raw link: identify's experiments are paced by the host
    # (test_identify.py, HOST_LINK and PACED).
    sim = Simulator(state_dir=str(tmp_path / "state"), plant=str(PLANTS / file), host_link=HOST_LINK,
                    paced=PACED).start()
    for line in built:
        assert sim.control(line).strip() == "ok", line
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.write("high_voltage", 12600)  # the 12 V servo's supply
        s.write("power_limit", 60000)   # and its stall power
        sim.wait_until(lambda: s.read("status") == 0, 2.0)  # the supply's trip at power-up has cleared
    return sim


def hold_errors(sim, s, stall_nm: float) -> list:
    """|angle| (decidegrees) holding 0, 1.5 s after each load change: on,
    reversed, off."""
    s.move(0, interval_ms=300)
    sim.sleep(1.0)
    out = []
    for share in (LOAD_SHARE, -LOAD_SHARE, 0.0):
        assert sim.control(f"load {share * stall_nm:.4f}").strip() == "ok"
        sim.sleep(1.5)
        out.append(abs(s.read_motion().angle_decideg))
    return out


@pytest.mark.parametrize("file", PLANT_FILES)
def test_identify_tune_and_store_meet_the_figures(tmp_path, file):
    plant = tomllib.loads((PLANTS / file).read_text())
    truth = at_the_output(plant)
    sim = start(tmp_path, file, BUILT)
    try:
        with sim.bus(timeout=0.2) as bus:
            s = Servo(bus, 1)
            c = calibrate(s, sim.sleep)
            assert c.current_zero == 18 and c.reversed, c
            factory = check_step(s, sim.sleep)
            drive = identify(s, sim.sleep)
            errors = relative_errors(drive, truth)
            assert all(abs(e) <= 0.15 for e in errors.values()), errors
            t = tune(drive, s.read("gear_ratio"))
            assert t.phase_margin_deg >= 40 and t.gain_margin_db >= 10, t
            s.write_drive(t.items)  # as tune does: in an order each step of which is stable
            steps = [check_step(s, sim.sleep, target) for target in (450, -450)]
            holds = hold_errors(sim, s, plant["published_stall_torque_nm"])
            print(file, f"factory {factory}; {t.bandwidth_hz:.2f} Hz kp {t.kp} ki {t.ki} kd {t.kd} "
                  f"PM {t.phase_margin_deg:.0f} GM {t.gain_margin_db:.1f}; steps {steps}; holds {holds}")
            assert all(over <= OVERSHOOT_MOST and error <= SETTLED_MOST for over, error in steps), steps
            assert all(error <= HOLD_MOST for error in holds), holds
        sim.stop()
        sim.start()  # the tuned items are the servo's now
        with sim.bus(timeout=0.2) as bus:
            s = Servo(bus, 1)
            assert {name: s.read(name) for name in t.items} == t.items
    finally:
        finish(sim, [1])


def test_the_60_kg_plant_needs_it(tmp_path):
    """The factory items are the reference's: on the 60 kg cm plant a 45
    degree move overshoots by more than the 1 degree the figures allow."""
    sim = start(tmp_path, "class_60kgcm.toml")
    try:
        with sim.bus(timeout=0.2) as bus:
            over, _ = check_step(Servo(bus, 1), sim.sleep)
            assert over > OVERSHOOT_MOST, over
    finally:
        finish(sim, [1])


def test_the_command_shows_gains_and_margins_and_a_dry_run_writes_nothing(tmp_path, capsys):
    sim = start(tmp_path, "reference_st3215.toml")
    try:
        with sim.bus(timeout=0.2) as bus:
            before = {name: Servo(bus, 1).read(name) for name in ("gain_kp", "gain_kd", "torque_constant")}
        assert main(["--port", sim.url, "tune", "1", "--dry-run"], clock=sim.clock_s) == 0
        out = capsys.readouterr().out
        assert "gains for 8.00 Hz" in out and "phase margin" in out and "dry run: nothing written" in out, out
        with sim.bus(timeout=0.2) as bus:
            assert {name: Servo(bus, 1).read(name) for name in before} == before
        assert main(["--port", sim.url, "tune", "1", "--bandwidth", "500"], clock=sim.clock_s) != 0
        assert "at most" in capsys.readouterr().err
    finally:
        finish(sim, [1])


def test_a_check_that_does_not_arrive_fails_and_puts_the_gains_back(tmp_path, capsys):
    """With angle limits of +-10 deg (--past-limits: the horn is free), the
    check's 45 deg move stops at 10: tune said "written and kept ... 35.0
    deg from the target" and exited 0. Now it fails, and the items it had
    are put back."""
    sim = start(tmp_path, "reference_st3215.toml")
    try:
        with sim.bus(timeout=0.2) as bus:
            s = Servo(bus, 1)
            s.write("angle_max", 100)
            s.write("angle_min", -100)
            before = {name: s.read(name) for name in ("gain_kp", "gain_kd", "torque_constant")}
        assert main(["--port", sim.url, "tune", "1", "--past-limits"], clock=sim.clock_s) == 1
        err = capsys.readouterr().err
        assert "ended 35.0 deg from its target" in err and "put back" in err, err
        with sim.bus(timeout=0.2) as bus:
            assert {name: Servo(bus, 1).read(name) for name in before} == before
    finally:
        finish(sim, [1])
