"""The virtual boards' USB-serial adapter model (vboard/usb.py) against the
fixed byte timelines servo_sim's model is tested on
(tests/unit/sim_usb_timelines.txt, tests/unit/test_sim_usb.c): the same
hand-overs, in whole microseconds, and none before the byte it waits for."""
from pathlib import Path

import pytest

from vboard.usb import Adapter

TIMELINES = Path(__file__).resolve().parents[2] / "tests" / "unit" / "sim_usb_timelines.txt"


def _cases():
    for line in TIMELINES.read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            left, want = line.split("=")
            mode, baud, *words = left.split()
            times = []
            for w in words:
                a, _, rest = w.partition("+")
                step, _, count = rest.partition("x")
                times += [int(a) + int(step or 0) * i for i in range(int(count or 1))]
            yield pytest.param(mode, int(baud), times, want.strip(), id=f"{mode}-{baud}-{words[0]}")


def handovers(mode, baud, times) -> str:
    a, i, out = Adapter(mode), 0, []
    while len(out) < 10000:
        due = a.due_s()
        if i < len(times) and times[i] <= due * 1e6:
            a.hold(i & 255, times[i] / 1e6, baud)
            i += 1
            continue
        if due == float("inf"):
            return " ".join(out)
        data, _ = a.take(due)
        out.append(f"{round(due * 1e6)}:{len(data)}")
    raise AssertionError(f"{mode}: no end of hand-overs")


@pytest.mark.parametrize("mode, baud, times, want", list(_cases()))
def test_the_same_hand_overs_as_servo_sim(mode, baud, times, want):
    assert handovers(mode, baud, times) == want


def test_a_packet_ending_just_after_a_frame_is_not_stuck():
    """64 bytes, the last ending 0.4 us after the 2 ms frame: handed over."""
    a = Adapter("usb")
    for i in range(64):
        a.hold(i, 0.0020004 - 63e-5 + i * 1e-5, 1_000_000)
    data, _ = a.take(a.due_s())
    assert len(data) == 64 and not a.held
