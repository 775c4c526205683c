"""The angle a servo reads after a power cycle is the same on servo_sim and
on both virtual boards (the F103 and F030 images): the horn in the turn
around its zero (item 90), -180..180 deg, whichever side of the zero the
encoder's count is. servo_sim and the F030 read -30 deg as 330 deg, and the
F103 read its first encoder value before the ADC's first scan (up to a turn
off with a zero). Time is each target's simulated time, run ahead while the
test waits on it (fast)."""
import pytest

from servoctl.servo import Servo
from servoctl.sim import Simulator

TARGETS = [None, "stm32f103", "stm32f030k6"]  # None: servo_sim


def angles_after_power_cycles(tmp_path, board, zero, angles, offset=0) -> list:
    """The same sequence on one target: the zero set, then for each angle a
    move there and a power cycle; (multi-turn angle, ReadAngle) read after
    each, in 0.1 deg."""
    sim = Simulator(ids=[1], state_dir=str(tmp_path / (board or "host")), board=board, fast=True).start()
    try:
        with sim.bus(timeout=0.3) as bus:
            s = Servo(bus, 1)
            # A write that meets a page erase is carried out but not
            # answered (docs/decisions-hardware.md): servoctl reads it back.
            for name, value in (("soft_start_on", 0), ("encoder_zero", zero), ("center_offset", offset)):
                s.write(name, value)
            read = []
            for angle in angles:
                sim.control("powercycle 1")
                sim.sleep(0.6)  # the bootloader's window, then the application
                s.move(angle, interval_ms=1000)
                sim.sleep(1.5)
                sim.control("powercycle 1")
                sim.sleep(0.6)
                read.append((s.multi_turn_angle()[0], s.angle()))
            return read
    finally:
        sim.stop()


@pytest.mark.parametrize("zero, offset, angles", [(0, 0, [-301, 1300, -1300]), (1000, 0, [1300, -301]),
                                                  (0, 1000, [1300, -1300]), (1000, -1000, [-1300, 1300])])
def test_a_power_cycle_reads_the_same_angle_on_servo_sim_and_both_boards(tmp_path, zero, offset, angles):
    """With a center offset (53) too: the reading after it is -180..180 deg
    (with an offset of 100 deg a horn at 130 deg read -230 deg)."""
    read = {board: angles_after_power_cycles(tmp_path, board, zero, angles, offset) for board in TARGETS}
    print(read)
    for board, got in read.items():
        for (multi, single), angle in zip(got, angles):
            assert abs(multi - angle) <= 3, f"{board or 'servo_sim'} read {multi / 10} deg at {angle / 10} deg"
            assert multi == single  # in turn 0: the multi-turn angle is ReadAngle's
    for board in TARGETS[1:]:  # each target's own plant settles a little differently
        assert all(abs(a[0] - b[0]) <= 5 for a, b in zip(read[None], read[board])), read
