"""Application images for the bootloader (docs/packets.md, "Firmware
update"): a 256-byte header, then the application from its vector table on.
The layout is firmware/bootloader/app_image.h's."""
import struct
import zlib
from dataclasses import dataclass
from pathlib import Path

from .protocol import UsageError

MAGIC = 0x50415653  # "SVAP"
FORMAT = 1
HEADER_SIZE = 256
CHECKED = 24  # bytes the header's own CRC covers

# Boards images are built for (the header's board field).
BOARDS = {"stm32f103": 0x0103, "qemu_stm32vl": 0x0100, "sim": 0x5100}


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
        raise UsageError("the application binary is empty")
    if not 0 <= version <= 0xFFFF or not 0 <= board <= 0xFFFF:
        raise UsageError("version and board are 16-bit numbers")
    if len(code) % 2:
        code += b"\xff"  # whole half-words; 0xFF is what erased flash reads
    head = struct.pack("<IHHIIH6x", MAGIC, FORMAT, board, len(code), zlib.crc32(code), version)
    head += struct.pack("<I", zlib.crc32(head))
    return head + b"\xff" * (HEADER_SIZE - len(head)) + code


def parse(data: bytes) -> Image:
    """Checks an image file as the bootloader would; UsageError if it is not one."""
    if len(data) < HEADER_SIZE + 2:
        raise UsageError("not an update image: shorter than its header")
    magic, fmt, board, size, crc, version = struct.unpack_from("<IHHIIH", data)
    (head_crc,) = struct.unpack_from("<I", data, CHECKED)
    if magic != MAGIC:
        raise UsageError("not an update image (no SVAP header): build one with 'servoctl image'")
    if head_crc != zlib.crc32(data[:CHECKED]) or fmt != FORMAT:
        raise UsageError("the image's header is damaged")
    code = data[HEADER_SIZE:HEADER_SIZE + size]
    if len(code) != size or zlib.crc32(code) != crc:
        raise UsageError("the image's code does not match its CRC: the file is damaged or cut short")
    return Image(data=data[:HEADER_SIZE + size], size=size, crc=crc, version=version, board=board)


def load(path: str) -> Image:
    try:
        return parse(Path(path).read_bytes())
    except OSError as e:
        raise UsageError(f"cannot read {path}: {e.strerror}") from e


def make(binary: str, version: str, board: str, output: str) -> bytes:
    """Reads an application binary, writes its update image; the image's
    bytes. board: a name of BOARDS or a number; version: a number."""
    number = BOARDS.get(board)
    if number is None:
        try:
            number = int(board, 0)
        except ValueError:
            raise UsageError(f"board must be one of {', '.join(BOARDS)} or a number, "
                             f"not {board!r}") from None
    try:
        version_number = int(version, 0)
    except ValueError:
        raise UsageError(f"version must be a number, not {version!r}") from None
    try:
        code = Path(binary).read_bytes()
    except OSError as e:
        raise UsageError(f"cannot read {binary}: {e.strerror}") from e
    data = build(code, version_number, number)
    try:
        Path(output).write_bytes(data)
    except OSError as e:
        raise UsageError(f"cannot write {output}: {e.strerror}") from e
    return data


def main(argv=None) -> int:
    """python3 -m servoctl.image BIN --version V --board B -o OUT (the build's
    post-link step; servoctl image is the same for users)."""
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
    except UsageError as e:
        print(f"servoctl.image: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
