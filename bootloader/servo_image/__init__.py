"""Application images for the bootloader (docs/packets.md, "Firmware
update"): a 256-byte header, then the application from its vector table on.
The layout is bootloader/include/bootloader/app_image.h's. Standard library only,
beside the bootloader: the firmware's build makes each board's image with
it (run as a script), and servoctl's image and update commands use it
(servoctl.image, whose errors are servoctl's)."""
import struct
import zlib
from dataclasses import dataclass
from pathlib import Path

if __package__:
    from . import board_facts
else:  # the build runs this file as a script: its folder is on the path
    import board_facts



class ImageError(ValueError):
    """Not an image, not this board's application, or a file that cannot
    be read or written: the sentence says which."""

MAGIC = 0x50415653  # "SVAP"
FORMAT = 1
HEADER_SIZE = 256
CHECKED = 24  # bytes the header's own CRC covers

# The build's boards: each folder of firmware/boards with a board.h
# (BOARD_ID, the header's board field; the flash map and RAM the
# application's linker script is made from: hal/ports/stm32_common/linker/app.ld.in).
HEADER_SIZE_IN_SLOT = 256  # the image header before the application (app.ld.in)
STAY_WORD_BYTES = 16       # RAM's last bytes, left out of the application's
# Vector 7 (reserved by the core) carries "SB" and the board's ID
# (hal/ports/stm32_common/board_mark.h): boards that share a link address and a
# RAM size are told apart by it.
BOARD_MARK_OFFSET = 7 * 4
BOARD_MARK_TAG = 0x5342


@dataclass(frozen=True)
class Board:
    name: str
    id: int
    flash: tuple = None  # (first, end) of the application's code; None: not executed (host_sim)
    ram: tuple = None    # (first, end) of its RAM
    cpu: str = ""        # its chip family's CPU (board_facts.cpu): cortex-m0 builds the size-first image


def _read_board(folder: Path):
    d = board_facts.defines(folder)
    if "BOARD_ID" not in d:
        return None
    if d.get("BOARD_SIMULATED"):
        return Board(folder.name, d["BOARD_ID"])
    slot = d["BOARD_SLOT_BASE"]
    flash = (slot + HEADER_SIZE_IN_SLOT, slot + d["BOARD_SLOT_PAGES"] * d["BOARD_FLASH_PAGE"])
    ram = (d["BOARD_RAM_BASE"], d["BOARD_RAM_BASE"] + d["BOARD_RAM_SIZE"] - STAY_WORD_BYTES)
    return Board(folder.name, d["BOARD_ID"], flash, ram, board_facts.cpu(folder))


def boards() -> dict:
    """{name: Board} of every board the build knows; none where no
    firmware tree is found (board_facts.root(): servoctl installed without
    -e, run outside a clone and without $SERVO_FIRMWARE_ROOT)."""
    root = board_facts.find_root()
    if root is None:
        return {}
    folder = root / board_facts.BOARDS
    found = (_read_board(f) for f in sorted(folder.iterdir()) if (f / "board.h").is_file())
    return {b.name: b for b in found if b is not None}


BOARDS = {name: b.id for name, b in boards().items()}  # those of the tree found at import


def board_named(board_id: int) -> str:
    """A board ID as people know it: its folder's name, and the number."""
    known = boards()
    if not known:
        return f"board 0x{board_id:04x} (unnamed: no firmware tree found; set {board_facts.ENV})"
    name = next((b.name for b in known.values() if b.id == board_id), None)
    return f"{name} (0x{board_id:04x})" if name else f"an unknown board (0x{board_id:04x})"


def check_code(code: bytes, board: Board) -> None:
    """Refuses what cannot be this board's application from its vector
    table: an ELF file, a first two words that are not a stack pointer in
    its RAM and a Thumb reset handler in its code, or a board mark (vector
    7) that is not this board's."""
    if code[:4] == b"\x7fELF":
        raise ImageError("that is an ELF file: give the application's raw binary (the build's "
                         f"servo_{board.name}.bin, or 'arm-none-eabi-objcopy -O binary')")
    if board.flash is None:
        return  # the simulator's slot holds bytes it never executes
    if len(code) < 8:
        raise ImageError(f"{len(code)} bytes cannot be an application: it starts with a vector table")
    sp, reset = struct.unpack_from("<II", code)
    first, end = board.flash
    if not board.ram[0] < sp <= board.ram[1] or sp % 4:
        raise ImageError(f"not a {board.name} application: its stack pointer 0x{sp:08x} is not in "
                         f"RAM (0x{board.ram[0]:08x}..0x{board.ram[1]:08x}); is it the bootloader, "
                         f"another board's binary, or not a binary at all?")
    if not reset & 1 or not first <= (reset & ~1) < first + len(code):
        raise ImageError(f"not a {board.name} application: its reset handler 0x{reset:08x} is not "
                         f"Thumb code in the image (0x{first:08x}..0x{first + len(code):08x}); "
                         f"is it the bootloader, or linked for another address?")
    if len(code) < BOARD_MARK_OFFSET + 4:
        raise ImageError(f"{len(code)} bytes cannot be an application: its vector table is longer")
    (mark,) = struct.unpack_from("<I", code, BOARD_MARK_OFFSET)
    if mark >> 16 != BOARD_MARK_TAG:
        raise ImageError(f"not a {board.name} application: its vector table has no board mark "
                         f"(vector 7 is 0x{mark:08x}); was it built by this project's build?")
    if mark & 0xFFFF != board.id:
        raise ImageError(f"not a {board.name} application: it was built for "
                         f"{board_named(mark & 0xFFFF)}")


@dataclass
class Image:
    data: bytes  # header and code, as written to the slot
    size: int  # code bytes
    crc: int
    version: int
    board: int


def build(code: bytes, version: int, board: int) -> bytes:
    """An image of `code` (the application's binary from its vector table)."""
    if not code:
        raise ImageError("the application binary is empty")
    if not 0 <= version <= 0xFFFF or not 0 <= board <= 0xFFFF:
        raise ImageError("version and board are 16-bit numbers")
    if len(code) % 2:
        code += b"\xff"  # whole half-words; 0xFF is what erased flash reads
    head = struct.pack("<IHHIIH6x", MAGIC, FORMAT, board, len(code), zlib.crc32(code), version)
    head += struct.pack("<I", zlib.crc32(head))
    return head + b"\xff" * (HEADER_SIZE - len(head)) + code


def parse(data: bytes) -> Image:
    """Checks an image file as the bootloader would; ImageError if it is not one."""
    if len(data) < HEADER_SIZE + 2:
        raise ImageError("not an update image: shorter than its header")
    magic, fmt, board, size, crc, version = struct.unpack_from("<IHHIIH", data)
    (head_crc,) = struct.unpack_from("<I", data, CHECKED)
    if magic != MAGIC:
        raise ImageError("not an update image (no SVAP header): build one with 'servoctl image'")
    if head_crc != zlib.crc32(data[:CHECKED]) or fmt != FORMAT:
        raise ImageError("the image's header is damaged")
    code = data[HEADER_SIZE:HEADER_SIZE + size]
    if len(code) != size or zlib.crc32(code) != crc:
        raise ImageError("the image's code does not match its CRC: the file is damaged or cut short")
    return Image(data=data[:HEADER_SIZE + size], size=size, crc=crc, version=version, board=board)


def load(path: str) -> Image:
    try:
        return parse(Path(path).read_bytes())
    except OSError as e:
        raise ImageError(f"cannot read {path}: {e.strerror}") from e


def make(binary: str, version: str, board: str, output: str) -> bytes:
    """Reads an application binary, writes its update image; the image's
    bytes. board: a name of BOARDS or a number; version: a number."""
    known = boards()
    found = known.get(board)
    if found is None:
        try:
            number = int(board, 0)
        except ValueError:
            number = None
        found = next((b for b in known.values() if b.id == number), None)
    if not known:
        try:
            board_facts.root()
        except board_facts.NoFirmwareTree as e:  # the boards' facts are not at hand
            raise ImageError(str(e)) from None
    if found is None:
        raise ImageError(f"board must be one of {', '.join(known)} (or its number), not {board!r}")
    try:
        version_number = int(version, 0)
    except ValueError:
        raise ImageError(f"version must be a number, not {version!r}") from None
    try:
        code = Path(binary).read_bytes()
    except OSError as e:
        raise ImageError(f"cannot read {binary}: {e.strerror}") from e
    check_code(code, found)
    data = build(code, version_number, found.id)
    try:
        Path(output).write_bytes(data)
    except OSError as e:
        raise ImageError(f"cannot write {output}: {e.strerror}") from e
    return data


def main(argv=None) -> int:
    """python3 bootloader/servo_image/__init__.py BIN --version V
    --board B -o OUT (the build's post-link step; servoctl image is the same
    for users)."""
    import argparse
    import sys

    ap = argparse.ArgumentParser(description=main.__doc__)
    ap.add_argument("binary")
    ap.add_argument("--version", required=True)
    ap.add_argument("--board", required=True)
    ap.add_argument("-o", "--output", required=True)
    args = ap.parse_args(argv)
    try:
        make(args.binary, args.version, args.board, args.output)
    except ImageError as e:
        print(f"servo_image: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
