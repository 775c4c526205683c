"""The bootloader's answers on the virtual boards (the shipped images), as
servoctl's update waits for them: polled as it starts, and the image check.
Runs in this process (power_cuts.py); time is the boards' simulated time."""
import pytest

from servoctl import protocol as p
from servoctl import update as upd
from servoctl.protocol import NoReply

from .power_cuts import Cuts
from .test_virtual_boards import BOARDS


@pytest.mark.parametrize("name", BOARDS)
def test_the_bootloader_answers_a_host_that_polls_it_as_it_starts(tmp_path, name):
    """UpdateEnter, then UpdateStatus every 70 ms from the moment its answer
    ends, as servoctl's update does with no delay between host and bus
    (the first request lands while the chip resets, a byte of it begun
    before the bootloader's receiver was on): the bootloader answers the
    second or third, and each after it within 10 ms (from the check it made
    at start: the image's CRC takes 66 ms on the G0, more than servoctl's
    50 ms wait)."""
    cuts = Cuts(name, str(tmp_path / "state"))
    try:
        cuts.host.request(p.UPDATE_ENTER, bytes([1]))
        polls, answered = 0, False
        while not answered and polls < 3:
            polls += 1
            try:
                answered = cuts.host.request(p.UPDATE_STATUS, bytes([1]), timeout=0.05)[1] == 1
            except NoReply:
                cuts.host.sleep(0.02)
        assert answered, f"no answer to {polls} polls"
        for _ in range(3):
            assert cuts.host.request(p.UPDATE_STATUS, bytes([1]), timeout=0.01)[1] == 1
    finally:
        cuts.close()


@pytest.mark.parametrize("name", BOARDS)
def test_the_image_check_answers_within_servoctls_allowance(tmp_path, name):
    """UpdateVerify reads the whole image for its CRC: its answer comes
    within the wait servoctl gives it (update.CHECK_MS_PER_KB)."""
    cuts = Cuts(name, str(tmp_path / "state"))
    try:
        cuts.host.request(p.UPDATE_ENTER, bytes([1]))
        cuts.host.sleep(0.1)
        assert cuts.host.request(p.UPDATE_STATUS, bytes([1]), timeout=0.05)[1] == 1
        begun = cuts.runner.now_s
        c = cuts.host.request(p.UPDATE_VERIFY, bytes([1]), timeout=1.0)
        took_ms = (cuts.runner.now_s - begun) * 1000
        verdict, size = c[1], int.from_bytes(c[2:6], "little")
        print(f"{name}: UpdateVerify of {size} B answered after {took_ms:.1f} ms, "
              f"{took_ms / (size / 1024):.2f} ms/KB")
        assert verdict == 0 and size > 16 * 1024
        wire_ms = (6 + 19) * 10 / 115200 * 1000  # the request's and the answer's bytes
        assert took_ms <= upd.CHECK_MS_PER_KB * size / 1024 + wire_ms + 1.0
    finally:
        cuts.close()
