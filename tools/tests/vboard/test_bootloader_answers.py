"""The bootloader's answers on the virtual boards (the shipped images), as
servoctl's update waits for them: polled as it starts, and the image check.
Runs in this process (power_cuts.py); time is the boards' simulated time."""
import struct
import zlib

import pytest

from servoctl import protocol as p
from servoctl import update as upd
from servoctl.protocol import NoReply

from vboard.board import board_h

from .power_cuts import Cuts
from .test_power_cuts import RECORD
from .test_virtual_boards import BOARDS

RECORD_MAGIC = b"\xf1\xc0"  # a config record's first bytes (config_record.h)


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


@pytest.mark.parametrize("name", BOARDS)
def test_the_bootloader_answers_where_the_application_did(tmp_path, name):
    """A newest config record whose CRC checks but whose items this
    firmware refuses (another firmware's ranges: here ID 7 with an angle
    limit out of range): the application loads the record before it (ID 1),
    the bootloader's own reading would take ID 7. Entered by UpdateEnter it
    answers at the ID the application answered at."""
    cuts = Cuts(name, str(tmp_path / "state"))
    try:
        assert cuts.in_application()
        h = board_h(name)
        page0 = h["BOARD_CONFIG_PAGE0"]
        raw = bytes(cuts.board.flash_mem.read(page0 - cuts.board.flash_base, h["BOARD_FLASH_PAGE"]))
        starts = [at for at in range(0, len(raw) - RECORD + 1, RECORD) if raw[at:at + 2] == RECORD_MAGIC]
        newest = bytearray(raw[starts[-1]:starts[-1] + RECORD])
        struct.pack_into("<I", newest, 4, struct.unpack_from("<I", newest, 4)[0] + 1)  # its sequence
        newest[14] = 7  # the servo ID
        struct.pack_into("<h", newest, 12 + 26, -32768)  # angle_max, out of its range
        struct.pack_into("<I", newest, RECORD - 4, zlib.crc32(bytes(newest[:RECORD - 4])))
        cuts.write_flash(page0 + starts[-1] + RECORD, bytes(newest))
        cuts.flash.persist(0, cuts.board.flash_size)
        cuts.board.power_cycle()
        assert cuts.in_application(2.0)
        cuts.host.request(p.PING, bytes([1]), timeout=0.05)  # the application loaded ID 1
        st = upd.enter_bootloader(cuts.host, 1)
        assert st.mode == upd.MODE_BOOTLOADER
        with pytest.raises(NoReply):
            cuts.host.request(p.PING, bytes([7]), timeout=0.05)
    finally:
        cuts.close()
