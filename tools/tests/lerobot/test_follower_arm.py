"""servoctl.arm, the LeRobot follower's library, at the edges a user meets
first, on servo_sim (no LeRobot needed): the first actions after connect,
a joint resting outside its limits, a run that ended without putting the
watchdog back, two servos at one joint's ID, and a new arm taken for a
calibrated one. Time is the simulator's."""
import logging

import pytest

from servoctl.arm import Arm, JointSilent
from servoctl.servo import Servo
from servoctl.sim import Simulator

FPS = 30
FACTORY_WATCHDOG = (0, 1)  # off, damp (items 64, 65 at power-up)


@pytest.fixture(autouse=True)
def state_dir(tmp_path, monkeypatch):
    """The watchdog's records in the test's own folder, not the user's."""
    monkeypatch.setenv("SERVOCTL_STATE_DIR", str(tmp_path / "state"))
    return tmp_path / "state"


def watchdog(bus, servo_id: int) -> tuple:
    s = Servo(bus, servo_id)
    return s.read("watchdog_ms"), s.read("watchdog_action")


def test_the_first_actions_ramp_from_where_the_arm_is():
    """A leader 40 deg away: the follower's horn went there at up to 740
    deg/s (a 34 deg jump in two frames in a recorded episode); now at the
    documented 45 deg/s, then it follows freely."""
    with Simulator(ids=[1, 2], paced=True) as sim:
        bus = sim.bus()
        arm = Arm(bus, {"a": 1, "b": 2}, fps=FPS, watchdog_ms=0).open()
        held = arm.hold_here()
        goal = held["a"] + 40.0
        t0, peak, reached_s = sim.clock_s(), 0.0, None
        for k in range(2 * FPS):
            arm.send({"a": goal})
            while sim.clock_s() < t0 + (k + 1) / FPS:
                sim.sleep(0.005)
                peak = max(peak, abs(sim.state(1)["velocity"]))
            if reached_s is None and abs(sim.state(1)["angle"] - goal) < 0.5:
                reached_s = sim.clock_s() - t0
        # 45 deg/s, give or take the servo's ripple on frames 30-35 ms apart (the paced clock)
        assert 40 <= peak <= 56, peak
        # 40 deg at 45 deg/s (0.89 s), a quarter second to speed up and one to slow down
        assert reached_s is not None and 1.0 <= reached_s <= 1.3, reached_s
        assert "a" not in arm.ramp.joints  # caught up: it follows freely from here (b, never asked, ramps still)
        assert arm.send({"a": goal - 20.0})["a"] == pytest.approx(goal - 20.0, abs=0.1)


def test_no_ramp_when_turned_off():
    with Simulator(ids=[1], paced=True) as sim:
        arm = Arm(sim.bus(), {"a": 1}, fps=FPS, watchdog_ms=0, ramp_speed_deg_s=0).open()
        held = arm.hold_here()
        sim.sleep(0.01)
        assert arm.send({"a": held["a"] + 20.0})["a"] == pytest.approx(held["a"] + 20.0, abs=0.1)


def test_a_joint_resting_outside_its_limits_ramps_from_the_nearest(monkeypatch):
    """A joint that settled a hair past its limit (reads 37.3, limits
    +-37.2), or was pushed far past one (136.2, limits -36.9..38.5): the
    first frame raised ValueOutOfRange (the ramp started where it was,
    outside). Now it goes to the nearest limit at the ramp's speed at
    connect, and the first actions, inside and outside, ramp from there."""
    limits = {"a": (-37.2, 37.2), "b": (-36.9, 38.5), "c": (-37.2, 37.2)}
    action = {"a": 10.0, "b": -90.0, "c": -80.0}  # inside; outside, across the range; outside, where it is
    with Simulator(ids=[1, 2, 3], paced=True) as sim:
        bus = sim.bus()
        for servo_id, deg in ((1, 37.35), (2, 136.2), (3, -60.0)):
            s = Servo(bus, servo_id)
            s.write("angle_limit_on", 0)
            s.move_to(deg, duration_s=1.0, wait=True)
            s.stop("release")  # at rest there, as a hand left it
        arm = Arm(bus, {"a": 1, "b": 2, "c": 3}, fps=FPS, watchdog_ms=0)
        arm.store_ranges(limits)
        here = arm.open().positions()
        assert 37.2 < here["a"] <= 37.5 and here["b"] > 135 and here["c"] < -59, here
        peak, sleep = [0.0], bus.sleep

        def sampled(seconds):  # the horns' speed while connect takes them to their limits
            sleep(seconds)
            peak[0] = max([peak[0]] + [abs(sim.state(i)["velocity"]) for i in (1, 2, 3)])

        monkeypatch.setattr(bus, "sleep", sampled)
        held = arm.hold_here()
        monkeypatch.undo()
        assert held == {"a": 37.2, "b": 38.5, "c": -37.2}
        t0 = sim.clock_s()
        for k in range(3 * FPS):
            sent = arm.send(action)
            assert all(limits[n][0] <= d <= limits[n][1] for n, d in sent.items()), sent
            while sim.clock_s() < t0 + (k + 1) / FPS:
                sim.sleep(0.005)
                for servo_id, (name, (low, high)) in enumerate(limits.items(), start=1):
                    horn = sim.state(servo_id)
                    assert low - 0.1 <= horn["angle"] <= high + 0.1, (name, horn["angle"])
                    peak[0] = max(peak[0], abs(horn["velocity"]))
        assert peak[0] <= 56, peak[0]  # the ramp's 45 deg/s, and the ripple the first test allows
        assert [round(sim.state(i)["angle"]) for i in (1, 2, 3)] == [10, -37, -37]
        said = arm.limits[1].check(1, 400)  # were a setpoint refused, the advice is a calibrated arm's
        assert "calibrate again" in said and "angle_limit_on 0" not in said, said


def test_a_new_arm_is_not_taken_for_a_calibrated_one():
    """Factory servos keep their angle limits on (+-135 deg, item 48 = 1):
    a new arm counted as calibrated, and connect() never asked for it.
    Calibrated now means ranges stored by a calibration, not the factory's."""
    with Simulator(ids=[1, 2], fast=True) as sim:
        bus = sim.bus()
        arm = Arm(bus, {"a": 1, "b": 2}, watchdog_ms=0).open()
        assert not arm.ranges_stored()
        arm.set_zero_here()  # the documented calibration: the middle, then the ranges (joints.calibrate)
        arm.store_ranges({"a": (-41.3, 36.8), "b": (-90.0, 88.2)})
        assert arm.ranges_stored()
        assert Arm(bus, {"a": 1, "b": 2}, watchdog_ms=0).open().ranges_stored()  # the next connect


def test_a_run_that_did_not_end_leaves_its_watchdog_not_taken_for_the_servos_own(caplog):
    """A run that ended without close() (a closed terminal) left 500 ms,
    hold on the servos; the next clean run read that as the setting to put
    back, and a later 3 s move stopped after 0.5 s ("limiter watchdog")."""
    # Paced: its clock stands still between the test's waits, so a loaded PC
    # slow between the runs does not let the first run's 500 ms watchdog act.
    with Simulator(ids=[1, 2], paced=True) as sim:
        bus = sim.bus()
        Arm(bus, {"a": 1, "b": 2}).open().hold_here()  # and never closed
        assert watchdog(bus, 1) == (500, 0)
        with caplog.at_level(logging.WARNING, logger="servoctl.arm"):
            arm = Arm(bus, {"a": 1, "b": 2}).open()
        arm.hold_here()
        arm.close()
        assert [watchdog(bus, i) for i in (1, 2)] == [FACTORY_WATCHDOG] * 2
        assert "a (servo 1): its bus watchdog holds 500 ms, hold, which a run that did not end cleanly wrote; " \
               "its own setting, off (damp)" in caplog.text, caplog.text
        s = Servo(bus, 1)
        s.move_to(30, duration_s=3.0)
        sim.sleep(3.3)
        assert abs(sim.state(1)["angle"] - 30) < 0.5  # the move ran its 3 s, no watchdog stopped it
        assert "watchdog" not in [f.kind for f in s.faults()]


def test_a_record_the_servo_no_longer_matches_is_dropped(state_dir):
    """Set since (or power-cycled: items 64-65 are RAM), the servo's value
    is its own again: a stale record does not put an old one back."""
    with Simulator(ids=[1], fast=True) as sim:
        bus = sim.bus()
        Arm(bus, {"a": 1}).open()  # never closed: a record of (0, damp) is left
        Servo(bus, 1).write("watchdog_ms", 2000)  # the user's new setting
        arm = Arm(bus, {"a": 1}).open()
        arm.close()
        assert watchdog(bus, 1) == (2000, 0)
        assert not list((state_dir / "watchdog").glob("*.json"))


def test_a_joint_whose_id_two_servos_hold_is_reported_as_shared():
    """Two servos at ID 2 answer the Sync Monitor at once and garble each
    other: the plugin said "did not answer ... is it powered, its cable
    in?", where servoctl scan says the truth."""
    with Simulator(ids=[1, 2, 2, 3], fast=True) as sim:
        arm = Arm(sim.bus(), {"a": 1, "b": 2, "c": 3}, watchdog_ms=0)
        with pytest.raises(JointSilent) as e:
            arm.positions()
    said = str(e.value)
    assert "b (servo 2)" in said and "TWO OR MORE SERVOS hold this ID" in said, said
    assert "servoctl id assign" in said and "cable" not in said, said
    assert "b" in e.value.joints

