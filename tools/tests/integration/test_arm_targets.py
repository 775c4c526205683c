"""servoctl.arm (the LeRobot plugins' Arm) on servo_sim: a target that is
not a number is refused on both protocols, and nothing is sent."""
import pytest

from servoctl.arm import Arm
from servoctl.errors import ValueOutOfRange
from servoctl.sim import Simulator


@pytest.mark.parametrize("firmware", ["servoctl", "maker"])
def test_a_target_of_nan_or_inf_is_refused_and_nothing_moves(firmware):
    with Simulator(ids=[1, 2], fast=True) as sim:
        arm = Arm(sim.bus(), {"a": 1, "b": 2}, firmware=firmware, watchdog_ms=0).open()
        held = arm.hold_here()
        for bad in (float("nan"), float("inf"), float("-inf")):
            with pytest.raises(ValueOutOfRange, match="finite"):
                arm.send({"a": bad})
        assert arm.targets == held
        sim.sleep(0.3)
        assert abs(sim.state(1)["angle"] - held["a"]) < 0.2  # the maker's took inf as its limit, 135 deg
