"""servoctl.arm (the LeRobot plugins' library) when no joint answers: a bus
at another baud rate than the servos' (a new servo is at 115200, the
plugins' default is 1 Mbaud) says so, not only "is its cable in?"."""
import pytest

from servoctl import link_rate
from servoctl.arm import Arm, JointSilent
from servoctl.sim import Simulator


def test_no_joint_answering_names_the_baud_rate():
    with Simulator(ids=[3, 7], fast=True) as sim:  # the servos at 115200
        link_rate.open_rate(sim.url, 1000000, str(sim.control_port))  # the host at 1 Mbaud
        with sim.bus(baud=1000000) as bus:
            arm = Arm(bus, {"base": 3, "elbow": 7}, watchdog_ms=0)
            with pytest.raises(JointSilent) as e:
                arm.positions()
    said = str(e.value)
    assert "base (servo 3), elbow (servo 7)" in said and "1000000 baud" in said, said
    assert e.value.joints == ["base", "elbow"]
