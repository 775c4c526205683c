"""The update image format: the header servoctl builds is the one the
bootloader checks (firmware/bootloader/app_image.h; test_bootloader.c's
test_the_header_matches_the_tool holds the same vector)."""
import struct

import pytest

from servoctl import image as img
from servoctl.protocol import UsageError


def test_the_header_matches_the_firmware():
    data = img.build(bytes(range(1, 9)), 0x0011, 0x0103)
    assert len(data) == img.HEADER_SIZE + 8
    magic, fmt, board, size, crc, version = struct.unpack_from("<IHHIIH", data)
    assert (magic, fmt, board, size, version) == (0x50415653, 1, 0x0103, 8, 0x0011)
    assert crc == 0x3FCA88C5
    assert struct.unpack_from("<I", data, 24)[0] == 0x790C7AB0
    assert data[28:img.HEADER_SIZE] == b"\xff" * (img.HEADER_SIZE - 28)


def test_parse_takes_what_build_makes_and_refuses_damage():
    data = img.build(b"\x01\x02\x03", 7, img.BOARDS["sim"])
    image = img.parse(data)
    assert (image.size, image.version, image.board) == (4, 7, 0x5100)  # padded to half-words
    with pytest.raises(UsageError, match="not an update image"):
        img.parse(b"\x00" * 300)
    broken = bytearray(data)
    broken[16] ^= 1  # the version, under the header's CRC
    with pytest.raises(UsageError, match="header is damaged"):
        img.parse(bytes(broken))
    with pytest.raises(UsageError, match="does not match its CRC"):
        img.parse(data[:-1])
