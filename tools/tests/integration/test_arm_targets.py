"""servoctl.arm (the LeRobot plugins' Arm) on servo_sim: a target that is
not a number is refused on both protocols, and nothing is sent."""
import pytest

from servoctl.arm import Arm
from servoctl.errors import UsageError, ValueOutOfRange
from servoctl.servo import Servo
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


@pytest.mark.parametrize("firmware", ["servoctl", "maker"])
def test_a_joint_beyond_one_turn_is_refused_when_held_not_spun_back(firmware):
    """After wheel mode a joint reads 1000 deg and more: its targets were
    clamped to its angle limits, and on the maker's protocol a frame that
    only held the arm spun the joint 175 deg within a second."""
    with Simulator(ids=[1, 2], fast=True) as sim:
        bus = sim.bus()
        Servo(bus, 1).wheel("run", 360)  # still turning as the arm is held
        sim.sleep(1.5)
        with pytest.raises(UsageError, match="--reset-turns"):
            Arm(bus, {"a": 1, "b": 2}, firmware=firmware, watchdog_ms=0).open().hold_here()
        sim.sleep(0.3)
        turned = sim.state(1)["angle"]
        assert turned > 400 and abs(sim.state(1)["velocity"]) < 1  # stopped, holding
        sim.sleep(0.5)
        assert abs(sim.state(1)["angle"] - turned) < 1


def test_a_calibration_cut_short_leaves_no_limits_of_the_old_zero():
    """A new zero with the range not stored after it (ENTER with nothing
    moved, Ctrl-C) kept the old limits' numbers on, counted as calibrated:
    25 deg off, in the new zero's frame. Then it turned them off, and the
    joint's range was gone. Now they move with the zero: the same horn
    positions, on."""
    with Simulator(ids=[1], fast=True) as sim:
        bus = sim.bus()
        arm = Arm(bus, {"a": 1}, firmware="servoctl", watchdog_ms=0).open()
        arm.store_ranges({"a": (-30, 30)})
        Servo(bus, 1).move_to(25, duration_s=0.3, wait=True)
        here = Servo(bus, 1).read_motion().angle_decideg
        arm.set_zero_here()
        with pytest.raises(UsageError, match="moved 0.5 deg"):
            arm.store_ranges({"a": (0.0, 0.5)})
        s = Servo(bus, 1)
        assert (s.read("angle_min"), s.read("angle_max")) == (-300 - here, 300 - here)  # not -300..300
        assert Arm(bus, {"a": 1}, firmware="servoctl", watchdog_ms=0).open().ranges_stored()
        arm.store_ranges({"a": (-20, 20)})
        assert arm.ranges_stored() and Servo(bus, 1).read("angle_max") == 200


def test_a_joints_range_past_180_from_the_new_zero_is_cut_not_turned_off():
    """Limits -130..130 with the horn resting at +60: a zero there would
    put them at -190..70, beyond the items' +-180, and the range was
    turned off without a word (the guards then saw no joint). Now the part
    that can be said stays on."""
    with Simulator(ids=[1], fast=True) as sim:
        bus = sim.bus()
        s = Servo(bus, 1)
        s.write("angle_max", 1300)
        s.write("angle_min", -1300)
        s.move_to(60, duration_s=0.4, wait=True)
        here = s.read_motion().angle_decideg
        Arm(bus, {"a": 1}, firmware="servoctl", watchdog_ms=0).open().set_zero_here()
        assert (s.read("angle_limit_on"), s.read("angle_min"), s.read("angle_max")) == (1, -1800, 1300 - here)
