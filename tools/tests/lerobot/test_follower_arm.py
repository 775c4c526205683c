"""servoctl.arm, the LeRobot follower's library, at the edges a user meets
first, on servo_sim (no LeRobot needed): the first actions after connect,
a run that ended without putting the watchdog back, and two servos at one
joint's ID. Time is the simulator's."""
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


def test_a_run_that_did_not_end_leaves_its_watchdog_not_taken_for_the_servos_own(caplog):
    """A run that ended without close() (a closed terminal) left 500 ms,
    hold on the servos; the next clean run read that as the setting to put
    back, and a later 3 s move stopped after 0.5 s ("limiter watchdog")."""
    with Simulator(ids=[1, 2], fast=True) as sim:
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
