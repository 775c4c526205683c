"""A board's facts as its folder of firmware/boards/ declares them, read in
one place for every tool (servo_image, which the build runs, servoctl.image,
vboard.board): board.h's plain
numbers (#define BOARD_X 0x... or decimal: the ID, the flash map, RAM, the
analogue front end), those of the headers it includes from firmware/boards/
(boards/common/reference_servo.h; host_sim's, the reference board's) where
the include stands, and the CPU of the chip family its board.cmake names
(include(.../cmake/family-NAME.cmake), whose SERVO_BOARD_CPU it is; a
board.cmake may also set SERVO_BOARD_CPU itself), and the part it names
(set(SERVO_BOARD_PART name)), whose facts are in hal/ports/parts.toml;
check() holds the board to them. Standard library only.

The firmware's tree they are read from (root()): the one this file is in
(a clone, the build's and an editable install's), else $SERVO_FIRMWARE_ROOT,
else the current directory's clone (it or a folder above it); an installed
copy (pip install ./tools) has none of its own."""
import os
import re
import sys
import tomllib
from pathlib import Path

HERE = Path(__file__).resolve().parent  # bootloader/servo_image/ of a clone
ENV = "SERVO_FIRMWARE_ROOT"
NO_TREE = f"no firmware tree found: run from a clone of the firmware or set {ENV}"
BOARDS = Path("firmware", "boards")  # within the tree
FAMILIES = Path("cmake")
PARTS = Path("hal", "ports", "parts.toml")


class NoFirmwareTree(LookupError):
    """No firmware tree to read a board's facts from (NO_TREE; with
    $SERVO_FIRMWARE_ROOT set, which folder it names)."""


def _is_tree(folder: Path) -> bool:
    return (folder / BOARDS).is_dir() and (folder / PARTS).is_file()


def find_root():
    """The firmware's tree (module docstring), or None."""
    candidates = [*HERE.parents[1:2]]
    if os.environ.get(ENV):
        candidates.append(Path(os.environ[ENV]).expanduser())
    here = Path.cwd()
    candidates += [here, *here.parents]
    return next((c.resolve() for c in candidates if _is_tree(c)), None)


def root() -> Path:
    """The firmware's tree; NoFirmwareTree, which says how to give one, if none."""
    found = find_root()
    if found is None:
        named = os.environ.get(ENV)
        raise NoFirmwareTree(f"{NO_TREE} ({ENV}={named} has no {BOARDS} and {PARTS})" if named else NO_TREE)
    return found


def boards_dir() -> Path:
    """firmware/boards of the tree (root())."""
    return root() / BOARDS

# Any #define of a BOARD_ name, its value to a comment: a fact is a plain
# number (what CMake, the linker script and the virtual boards read alike).
_DEFINE = re.compile(r"\s*#\s*define\s+(BOARD_\w+)(?:\s+(.*?))?\s*(?:(?://|/\*).*)?$")
_PLAIN = re.compile(r"0x[0-9a-fA-F]+|\d+")
_INCLUDE = re.compile(r'#include "(boards/[^"]+)"')
_CPU = re.compile(r"^set\(SERVO_BOARD_CPU (\S+)\)", re.M)
_FAMILY = re.compile(r"^include\(\S*family-([\w-]+)\.cmake\)", re.M)
_PART = re.compile(r"^set\(SERVO_BOARD_PART (\S+)\)", re.M)


def folder_of(board) -> Path:
    """A board's folder: a path as given, or its name under firmware/boards."""
    return Path(board) if isinstance(board, Path) else boards_dir() / board


def _numbers(header: Path, odd=None) -> dict:
    """A header's plain numbers, an included one's where it stands: a later
    #define overrides (host_sim's BOARD_ID after the reference board's).
    A BOARD_ value of this header that is not one is put in odd (a line
    each), if given; an included header's derived values are not facts."""
    out = {}
    for line in header.read_text().splitlines():
        included = _INCLUDE.match(line)
        if included:
            out.update(_numbers(root() / "firmware" / included.group(1)))
        found = _DEFINE.match(line)
        if found and found.group(2):  # not a guard
            if _PLAIN.fullmatch(found.group(2)):
                out[found.group(1)] = int(found.group(2), 0)
            elif odd is not None:
                odd.append(f"{header.name}: {found.group(1)} is {found.group(2)!r}: a board fact is a plain "
                           "number, decimal or 0x hex (no parentheses, suffix or expression)")
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
        text = (root() / FAMILIES / f"family-{family.group(1)}.cmake").read_text()
    found = _CPU.search(text)
    return found.group(1) if found else ""


def part_name(board) -> str:
    """The part its board.cmake names; "" for none (host_sim)."""
    cmake = folder_of(board) / "board.cmake"
    found = _PART.search(cmake.read_text()) if cmake.is_file() else None
    return found.group(1) if found else ""


def parts() -> dict:
    """{name: {fact: value}} of every part a board may name."""
    with (root() / PARTS).open("rb") as f:
        return tomllib.load(f)


def _regions(d: dict) -> list:
    """The flash map's regions, (name, first, bytes), as board.h has them."""
    page = d.get("BOARD_FLASH_PAGE", 0)
    out = []
    if "BOARD_BOOT_SIZE" in d:
        out.append(("the bootloader (BOARD_FLASH_BASE, BOARD_BOOT_SIZE)", d["BOARD_FLASH_BASE"],
                    d["BOARD_BOOT_SIZE"]))
    if "BOARD_SLOT_BASE" in d:
        out.append(("the slot (BOARD_SLOT_BASE, BOARD_SLOT_PAGES)", d["BOARD_SLOT_BASE"],
                    d.get("BOARD_SLOT_PAGES", 0) * page))
    for name in ("BOARD_FAULT_PAGE0", "BOARD_FAULT_PAGE1", "BOARD_CONFIG_PAGE0", "BOARD_CONFIG_PAGE1",
                 "BOARD_RAM_CONFIG_BASE"):
        if name in d:
            out.append((name, d[name], page))
    return out


def pin_name(pin: int) -> str:
    """A board.h pin, 0xPN (port P: 0 A, 1 B...; pin N), as its name: 0x1A is PB10."""
    return f"P{'ABCDEFG'[pin >> 4]}{pin & 0xF}" if 0 <= pin < 0x70 else f"0x{pin:X}"


def _pins(ranges: list) -> set:
    """The pins of parts.toml's ranges ("PA0-PA15"), as names."""
    out = set()
    for r in ranges:
        first, _, last = r.partition("-")
        last = last or first
        out |= {f"{first[:2]}{n}" for n in range(int(first[2:]), int(last[2:]) + 1)}
    return out


_PIN_FACTS = ("BOARD_BUS_TX_PIN", "BOARD_BRIDGE_IN1_PIN", "BOARD_BRIDGE_IN2_PIN")
_INSTANCES = (("BOARD_BUS_USART", "usarts", "USART"), ("BOARD_BRIDGE_TIMER", "timers", "TIM"))


def _pin_problems(d: dict, p: dict) -> list:
    """The pins and instances board.h names that its part lacks, where the
    part lists them (parts.toml: pins, usarts, timers, adc_inputs)."""
    out = []
    if "pins" in p:
        have = _pins(p["pins"])
        for fact in (f for f in _PIN_FACTS if f in d):
            if pin_name(d[fact]) not in have:
                out.append(f"{fact} 0x{d[fact]:02X} ({pin_name(d[fact])}) is not a pin of the part's "
                           f"package ({', '.join(p['pins'])})")
    for fact, key, what in _INSTANCES:
        if key in p and fact in d and d[fact] not in p[key]:
            out.append(f"{fact} {d[fact]}: the part has no {what}{d[fact]} (its {key}: "
                       f"{', '.join(str(n) for n in p[key])})")
    if "adc_inputs" in p:
        for fact in (f for f in d if f.startswith("BOARD_ADC_")):
            if not 0 <= d[fact] < p["adc_inputs"]:
                out.append(f"{fact} {d[fact]}: the part's ADC has inputs 0-{p['adc_inputs'] - 1} on its pins")
    return out


def check(board) -> list:
    """What in a board's declaration its part contradicts, a line each
    naming the fact and the part's own; [] when it fits. A board with
    no board.cmake (host_sim) is not built for a part."""
    folder = folder_of(board)
    if not (folder / "board.cmake").is_file():
        return []
    name = part_name(folder)
    known = parts()
    if name not in known:
        said = (f"names the part {name!r}, which hal/ports/parts.toml does not have" if name
                else "names no part: add set(SERVO_BOARD_PART name)")
        return [f"{folder.name}: board.cmake {said} (the parts: {', '.join(sorted(known))})"]
    p = known[name]
    odd = []
    d = _numbers(folder / "board.h", odd)
    if odd:
        return [f"{folder.name}: {line}" for line in odd]
    problems = []

    def say(text):
        problems.append(f"{folder.name}: {text} ({name})")

    if cpu(folder) != p["cpu"]:
        say(f"its family's CPU {cpu(folder) or 'none'} is not the part's {p['cpu']}")
    missing = [k for k in ("BOARD_FLASH_BASE", "BOARD_FLASH_PAGE", "BOARD_RAM_BASE", "BOARD_RAM_SIZE")
               if k not in d]
    if missing:
        say(f"board.h does not declare {', '.join(missing)}")
        return problems
    page, end = p["page_size"], p["flash_base"] + p["flash_size"]
    if d["BOARD_FLASH_PAGE"] != page:
        say(f"BOARD_FLASH_PAGE {d['BOARD_FLASH_PAGE']} is not the part's erase unit, {page} B: "
            "an erase would reach another region, or leave part of this one")
    if d["BOARD_FLASH_BASE"] != p["flash_base"]:
        say(f"BOARD_FLASH_BASE 0x{d['BOARD_FLASH_BASE']:08X} is not the part's flash, at 0x{p['flash_base']:08X}")
    regions = _regions(d)
    for what, first, size in regions:
        if first % page or size % page:
            say(f"{what} at 0x{first:08X}, {size} B, is not on the part's {page}-byte erase unit")
        if first < p["flash_base"] or first + size > end:
            say(f"{what} at 0x{first:08X}, {size} B, ends past the part's {p['flash_size'] // 1024} KB "
                f"of flash (0x{p['flash_base']:08X}-0x{end - 1:08X})")
    for i, (a, first_a, size_a) in enumerate(regions):
        for b, first_b, size_b in regions[i + 1:]:
            if first_a < first_b + size_b and first_b < first_a + size_a:
                say(f"{a} and {b} overlap")
    problems += [f"{folder.name}: {line} ({name})" for line in _pin_problems(d, p)]
    ram_end = p["ram_base"] + p["ram_size"]
    if d["BOARD_RAM_BASE"] != p["ram_base"] or d["BOARD_RAM_BASE"] + d["BOARD_RAM_SIZE"] > ram_end:
        say(f"BOARD_RAM_BASE 0x{d['BOARD_RAM_BASE']:08X} and BOARD_RAM_SIZE {d['BOARD_RAM_SIZE']} are not "
            f"within the part's {p['ram_size']} B of RAM at 0x{p['ram_base']:08X}")
    return problems


def main(argv) -> int:
    """board_facts.py --check [--facts] FOLDER: the build's reading of a
    board (cmake/arm-image.cmake): a line a problem against its part on
    stderr and 1; else, with --facts, board.h's numbers as NAME=decimal
    lines on stdout, and 0."""
    args = [a for a in argv if not a.startswith("--")]
    if "--check" not in argv or len(args) != 1:
        print("usage: board_facts.py --check [--facts] BOARD_FOLDER", file=sys.stderr)
        return 2
    folder = Path(args[0])
    found = check(folder)
    for line in found:
        print(f"board check: {line}", file=sys.stderr)
    if found:
        return 1
    if "--facts" in argv:
        print("".join(f"{name}={value}\n" for name, value in defines(folder).items()), end="")
        # The part's facts the C code is built with (its VTOR: boot_jump.c).
        part = parts().get(part_name(folder), {})
        if "vtor" in part:
            print(f"BOARD_PART_VTOR={int(part['vtor'])}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
