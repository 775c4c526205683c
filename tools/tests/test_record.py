"""servoctl record's time axis: the servo's profile start found from a
sample's setpoint, and the plan read before, during and after it."""
from servoctl.cli.cmd_record import _planned_at, _profile_start
from servoctl.profile import positions
from servoctl.servo import MotionSnapshot


def snapshot(setpoint):
    return MotionSnapshot(1, setpoint, setpoint, 600, 0, 0, 0, 1, 0, 0, 250, 0)


def test_the_profile_start_comes_from_the_setpoint_not_the_host():
    plan = positions(0, 600, 100, 300, 100)
    # The host's clock says 0.040 s; the servo's setpoint says 30 ms into
    # its profile: the profile began 10 ms after the host's reference.
    k = next(i for i, p in enumerate(plan) if p >= 60)
    samples = [(0.005, snapshot(0)), (0.010 + k / 1000.0, snapshot(round(plan[k])))]
    assert abs(_profile_start(samples, plan) - 0.010) < 0.0011
    assert _profile_start([(0.1, snapshot(0)), (0.2, snapshot(600))], plan) == 0.0  # none caught


def test_the_plan_before_during_and_after_the_profile():
    plan = positions(0, 600, 100, 300, 100)
    assert _planned_at(plan, -0.004) == (0.0, 0.0)  # before the first tick: the start
    deg, dps = _planned_at(plan, 0.250)
    assert abs(deg - plan[250] / 10.0) < 1e-9 and 100.0 < dps < 200.0
    assert _planned_at(plan, 9.0) == (60.0, 0.0)
