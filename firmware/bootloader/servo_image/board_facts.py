"""A board's facts as its folder of firmware/boards/ declares them, read in
one place for every tool (servo_image, which the build runs, servoctl.image,
vboard.board): board.h's plain
numbers (#define BOARD_X 0x... or decimal: the ID, the flash map, RAM, the
analogue front end), those of the headers it includes from firmware/boards/
(boards/common/reference_servo.h; host_sim's, the reference board's) where
the include stands, and the CPU of the chip family its board.cmake names
(include(.../cmake/family-NAME.cmake), whose SERVO_BOARD_CPU it is; a
board.cmake may also set SERVO_BOARD_CPU itself). Standard library only."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]  # firmware/bootloader/servo_image/
BOARDS_DIR = ROOT / "firmware" / "boards"
FAMILIES_DIR = ROOT / "cmake"

_DEFINE = re.compile(r"#define (BOARD_\w+) (0x[0-9a-fA-F]+|\d+)\b")
_INCLUDE = re.compile(r'#include "(boards/[^"]+)"')
_CPU = re.compile(r"^set\(SERVO_BOARD_CPU (\S+)\)", re.M)
_FAMILY = re.compile(r"^include\(\S*family-([\w-]+)\.cmake\)", re.M)


def folder_of(board) -> Path:
    """A board's folder: a path as given, or its name under firmware/boards."""
    return Path(board) if isinstance(board, Path) else BOARDS_DIR / board


def _numbers(header: Path) -> dict:
    """A header's plain numbers, an included one's where it stands: a later
    #define overrides (host_sim's BOARD_ID after the reference board's)."""
    out = {}
    for line in header.read_text().splitlines():
        included = _INCLUDE.match(line)
        if included:
            out.update(_numbers(ROOT / "firmware" / included.group(1)))
        found = _DEFINE.match(line)
        if found:
            out[found.group(1)] = int(found.group(2), 0)
    return out


def defines(board) -> dict:
    """board.h's plain numbers, {name: int}."""
    return _numbers(folder_of(board) / "board.h")


def cpu(board) -> str:
    """The board's CPU (cortex-m0, cortex-m3), from board.cmake or its
    family's settings; "" for a board without one (host_sim)."""
    cmake = folder_of(board) / "board.cmake"
    if not cmake.is_file():
        return ""
    text = cmake.read_text()
    family = _FAMILY.search(text)
    if family and not _CPU.search(text):
        text = (FAMILIES_DIR / f"family-{family.group(1)}.cmake").read_text()
    found = _CPU.search(text)
    return found.group(1) if found else ""
