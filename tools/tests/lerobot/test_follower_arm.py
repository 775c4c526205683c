"""servoctl.arm, the LeRobot follower's library, at the edges a user meets
first, on servo_sim (no LeRobot needed): the first actions after connect.
Time is the simulator's."""
import pytest

from servoctl.arm import Arm
from servoctl.sim import Simulator

FPS = 30


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
        assert not arm.ramping  # caught up: it follows freely from here
        assert arm.send({"a": goal - 20.0})["a"] == pytest.approx(goal - 20.0, abs=0.1)


def test_no_ramp_when_turned_off():
    with Simulator(ids=[1], paced=True) as sim:
        arm = Arm(sim.bus(), {"a": 1}, fps=FPS, watchdog_ms=0, ramp_speed_deg_s=0).open()
        held = arm.hold_here()
        sim.sleep(0.01)
        assert arm.send({"a": held["a"] + 20.0})["a"] == pytest.approx(held["a"] + 20.0, abs=0.1)
