"""The update image format: the header servoctl builds is the one the
bootloader checks (bootloader/include/bootloader/app_image.h; test_bootloader.c's
test_the_header_matches_the_tool holds the same vector)."""
import struct

import pytest

from servo_image import board_facts
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
    data = img.build(b"\x01\x02\x03", 7, img.BOARDS["host_sim"])
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


def test_the_boards_are_the_builds():
    """Every folder of firmware/boards with a board.h, the M0 included, with
    the ID and the memory map the build makes its linker scripts from."""
    folders = {f.name for f in board_facts.boards_dir().iterdir() if (f / "board.h").is_file()}
    boards = img.boards()
    assert set(boards) == folders >= {"stm32f103", "stm32f030k6", "qemu_stm32vl", "host_sim"}
    assert boards["stm32f030k6"].id == 0x0030 and boards["stm32f103"].id == 0x0103
    assert boards["stm32f030k6"].flash == (0x08001100, 0x08007000)  # 24 KB less the header
    assert boards["stm32f103"].ram == (0x20000000, 0x20005000 - 16)
    assert boards["host_sim"].id == 0x5100 and boards["host_sim"].flash is None  # never executed


def vectors(sp, reset, size=64, board=0x0030):
    """A vector table: stack pointer, reset handler, vector 7's board mark."""
    code = bytearray(struct.pack("<II", sp, reset) + b"\x00" * (size - 8))
    if board is not None:
        struct.pack_into("<I", code, img.BOARD_MARK_OFFSET, 0x53420000 | board)
    return bytes(code)


@pytest.mark.parametrize("code, why", [
    (b"\x7fELF\x01\x01\x01" + b"\x00" * 100, "that is an ELF file"),
    (b"hello, world, this is not firmware", "stack pointer 0x6c6c6568 is not in RAM"),
    (vectors(0x20000700, 0x0800074D), "reset handler 0x0800074d is not Thumb code in the image"),
    (vectors(0x20001000, 0x08001141), "stack pointer 0x20001000 is not in RAM"),  # the F030 has 4 KB
    (vectors(0x20000D20, 0x08001140), "is not Thumb code"),  # an even address: ARM state
    (vectors(0x20000D20, 0x08001141, size=0x300, board=None), "has no board mark"),
    (vectors(0x20000D20, 0x08001141, size=0x300, board=0x0103), r"built for stm32f103 \(0x0103\)"),
    (vectors(0x20000D20, 0x08001141, size=0x300, board=0x0777), r"built for an unknown board \(0x0777\)"),
])
def test_image_refuses_what_cannot_be_the_boards_application(tmp_path, code, why):
    binary = tmp_path / "app.bin"
    binary.write_bytes(code)
    with pytest.raises(UsageError, match=why):
        img.make(str(binary), "1", "stm32f030k6", str(tmp_path / "app.img"))
    assert not (tmp_path / "app.img").exists()


def test_image_takes_an_application_by_board_name_or_number(tmp_path):
    binary = tmp_path / "app.bin"
    binary.write_bytes(vectors(0x20000D20, 0x08001341, size=0x300))
    for board in ("stm32f030k6", "0x0030", "48"):
        img.make(str(binary), "0x0011", board, str(tmp_path / "app.img"))
        assert img.load(str(tmp_path / "app.img")).board == 0x0030
    with pytest.raises(UsageError, match="board must be one of host_sim, qemu_stm32vl, stm32f030k6, stm32f103"):
        img.make(str(binary), "1", "0x0777", str(tmp_path / "x.img"))


@pytest.mark.parametrize("built, packed_as, why", [
    ("stm32f103", "stm32f030k6", "not a stm32f030k6 application: its stack pointer"),  # 4 KB ring
    ("stm32f030k6", "stm32f103", r"not a stm32f103 application: it was built for stm32f030k6 \(0x0030\)"),
])
def test_one_boards_application_is_not_packed_for_another(tmp_path, built, packed_as, why):
    """Both applications link at 0x08001100; the F030's stack pointer lies
    in the F103's RAM as well: only the board mark tells that one apart.
    The build's own binaries (scripts/test.sh builds both before pytest)."""
    preset = "arm-m0" if built == "stm32f030k6" else "arm"
    binary = board_facts.root() / "build" / preset / "firmware" / "boards" / built / f"servo_{built}.bin"
    img.make(str(binary), "0x0011", built, str(tmp_path / "own.img"))  # its own board takes it
    with pytest.raises(UsageError, match=why):
        img.make(str(binary), "0x0011", packed_as, str(tmp_path / "other.img"))
    assert not (tmp_path / "other.img").exists()
