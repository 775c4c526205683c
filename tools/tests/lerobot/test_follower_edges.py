"""servoctl.arm at the edges an attacker found: a joint left out of the
first actions, a crash between the two watchdog writes, a servo that
holds the follower's own setting with no record of its own, a servo
power-cycled mid-run, records and IDs that are not what they should be.
On servo_sim; time is the simulator's."""
from servoctl.arm import Arm
from servoctl.sim import Simulator

from .test_follower_arm import FACTORY_WATCHDOG, FPS, state_dir, watchdog  # noqa: F401 - the fixture too

RAMP_TOP = 56  # 45 deg/s, give or take the servo's ripple on the paced clock's frames


def frames(sim, arm, t0: float, first: int, count: int, goal, watch: int) -> float:
    """count frames from frame first on (goal(k): the action), each on the
    simulated clock; the peak horn speed of servo watch."""
    peak = 0.0
    for k in range(first, first + count):
        arm.send(goal(k))
        while sim.clock_s() < t0 + (k + 1) / FPS:
            sim.sleep(0.005)
            peak = max(peak, abs(sim.state(watch)["velocity"]))
    return peak


def test_a_joint_left_out_of_the_first_action_still_ramps():
    """The first action named only a: b's gap was taken as 0, b left the
    ramp, and when first asked 40 deg away it jumped at the motor's top
    speed; a first send_action({}) took every joint out of the ramp."""
    with Simulator(ids=[1, 2], paced=True) as sim:
        arm = Arm(sim.bus(), {"a": 1, "b": 2}, fps=FPS, watchdog_ms=0).open()
        held = arm.hold_here()
        t0 = sim.clock_s()
        frames(sim, arm, t0, 0, 1, lambda k: {"a": held["a"] + 40}, 2)
        assert "b" in arm.ramp.joints  # not asked, not reached
        peak = frames(sim, arm, t0, 1, 45, lambda k: {"a": held["a"] + 40, "b": held["b"] + 40}, 2)
        assert peak <= RAMP_TOP, peak
    with Simulator(ids=[1, 2], paced=True) as sim:
        arm = Arm(sim.bus(), {"a": 1, "b": 2}, fps=FPS, watchdog_ms=0).open()
        held = arm.hold_here()
        t0 = sim.clock_s()
        assert arm.send({}) == {n: round(d, 1) for n, d in held.items()}
        assert arm.ramp.joints == {"a", "b"}
        peak = frames(sim, arm, t0, 1, 45, lambda k: {"a": held["a"] + 40, "b": held["b"] - 40}, 1)
        assert peak <= RAMP_TOP, peak
