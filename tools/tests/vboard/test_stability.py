"""Mistyped drive items on the shipped ARM images (both virtual boards): the
mistyped drive items are refused by the firmware's own check, and ReadStore
right after says why; servoctl's check refuses them before writing. Time is
the boards' simulated time."""
import pytest

from servoctl.errors import Refused, ValueOutOfRange
from servoctl.servo import Servo
from servoctl.sim import Simulator

from .test_virtual_boards import BOARDS, finish

TYPOS = [("torque_constant", 37140, 3714), ("gear_ratio", 3450, 345), ("gear_ratio", 32767, 345),
         ("torque_constant", 65535, 3714)]


@pytest.mark.parametrize("board", BOARDS)
def test_mistyped_drive_items_are_refused_on_the_real_images(tmp_path, board):
    sim = Simulator(ids=[1], state_dir=str(tmp_path / "state"), board=board, fast=True).start()
    try:
        with sim.bus(timeout=0.3) as bus:
            s = Servo(bus, 1)
            for name, value, factory in TYPOS:
                with pytest.raises(ValueOutOfRange, match="not written"):
                    s.write(name, value)  # servoctl's check
                with pytest.raises(Refused, match="would make its loop unstable"):
                    s.write(name, value, check=False)  # the firmware's
                assert s.read_store().flag_names() == ["unstable"]
                assert s.read(name) == factory
            assert s.read("oscillation_ms") == 300
            s.write("torque_constant", 3800, check=False)
            assert s.read_store().flag_names() == []
            sim.control("powercycle")
            sim.sleep(0.5)
            assert (s.read("torque_constant"), s.read("gear_ratio")) == (3800, 345)
    finally:
        finish(sim, [1])
