"""A robot loop that cannot keep its period says so, with the wire's limit
computed from the baud rate and the frames' sizes; one that can is paced
to its period on the bus's clock (here a clock the test moves: no host
time is judged)."""
import warnings

import pytest

from servoctl import protocol as p
from servoctl.errors import ValueOutOfRange
from servoctl.loop_rate import cycle_bytes, wire_limit_hz
from servoctl.stream import Limits, LoopLate, RobotLoop

SIX = [1, 2, 3, 4, 5, 6]


class ClockBus:
    """Answers nothing; its clock moves only when the loop sleeps, or the
    test says the host was slow."""

    def __init__(self, baud):
        self.now = 0.0
        self.sends = []
        self.stamp_arrivals = True
        self.serial = type("Port", (), {"baudrate": baud})()

    def clock(self):
        return self.now

    def sleep(self, seconds):
        self.now += seconds

    def send_burst(self, requests):
        self.sends.append(self.now)

    def read_response(self, code, servo_id, timeout=None, deadline=None):
        self.now += 0.002  # the cycle's wire time at 1 Mbaud; then no answer
        raise p.NoReply("nobody here")


def loop(bus, ids, period_s, **kw):
    return RobotLoop(bus, ids, period_s, limits={i: Limits() for i in ids}, **kw)


def test_the_wire_limit_is_the_cycles_bytes_at_the_baud_rate():
    # Six servos: a SyncCommand of six 9-byte StreamSetpoint records (5 + 3 +
    # 54 = 62 bytes), a Sync Monitor of six IDs (5 + 3 + 6 = 14) and six
    # 21-byte Monitor answers (126): 202 bytes, 10 bits each.
    assert cycle_bytes(SIX) == 62 + 14 + 6 * p.answer_frame_size(p.MONITOR) == 202
    assert wire_limit_hz(SIX, 115200) == pytest.approx(115200 / 10 / 202)  # 57.0 Hz


def test_a_period_the_wire_cannot_carry_is_refused():
    """60 Hz with six servos at 115 200 baud: the wire carries 57.0 cycles a
    second (on 7d81a12 the loop ran at 55.9 Hz and said nothing)."""
    with pytest.raises(ValueOutOfRange, match=r"60 Hz is beyond the wire: .* 202 bytes, 17.53 ms at 115200 "
                                              r"baud, so the wire allows at most 57.0 Hz"):
        loop(ClockBus(115200), SIX, 1 / 60)
    loop(ClockBus(1000000), SIX, 1 / 60)  # 495 Hz at 1 Mbaud: taken


def test_the_loop_is_paced_to_its_period():
    bus = ClockBus(1000000)
    robot = loop(bus, SIX, 0.02)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for _ in range(50):
            robot.cycle({i: 0.0 for i in SIX})
    gaps = [b - a for a, b in zip(bus.sends, bus.sends[1:])]
    assert gaps == pytest.approx([0.02] * 49)
    assert robot.rate().rate_hz == pytest.approx(50.0, rel=0.05)


def test_a_late_cycle_warns_with_the_wire_limit():
    bus = ClockBus(1000000)
    robot = loop(bus, SIX, 0.02)
    robot.cycle({i: 0.0 for i in SIX})
    bus.now += 0.05  # the host was away for two and a half periods
    with pytest.warns(LoopLate, match=r"cycle 2 began .* ms late: the loop cannot keep its 20 ms period .* "
                                      r"the wire allows 495.0 Hz at 1000000 baud"):
        robot.cycle({i: 0.0 for i in SIX})
    assert robot.late == 1
    # Then on from there, a period apart: no burst to catch up.
    robot.cycle({i: 0.0 for i in SIX})
    assert bus.sends[2] - bus.sends[1] == pytest.approx(0.02)


def test_an_unpaced_loop_runs_as_fast_as_the_bus_goes():
    bus = ClockBus(115200)
    robot = loop(bus, SIX, 0.02, pace=False)  # beyond the wire's 57 Hz: a benchmark's loop
    for _ in range(3):
        robot.cycle({i: 0.0 for i in SIX})
    assert robot.late == 0 and len(bus.sends) == 3


def test_a_stall_shorter_than_a_period_keeps_the_period_grid():
    """The host away for most of a period: the next cycle waits for its
    slot on the period's grid, not two cycles back to back."""
    bus = ClockBus(1000000)
    robot = loop(bus, SIX, 0.02)
    robot.cycle({i: 0.0 for i in SIX})  # at 0, 2 ms on the wire
    bus.now += 0.0195  # cycle 2 was due at 20 ms: now 21.5 ms
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # less than a period behind: no warning
        for _ in range(3):
            robot.cycle({i: 0.0 for i in SIX})
    assert bus.sends == pytest.approx([0.0, 0.04, 0.06, 0.08])
    assert robot.late == 0
