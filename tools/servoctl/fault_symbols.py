"""The functions and the board of an image's ELF (pyelftools, loaded only
where --elf is given; the LeRobot plugins reach fault_code.py, not this)."""
from . import extras
from .errors import UsageError

BOARD_MARK_TAG = 0x5342  # "SB": vector 7's high half (servo_image.BOARD_MARK_TAG)


class Symbols:
    """The functions of an image's ELF, by address (pyelftools)."""

    def __init__(self, path):
        try:
            from elftools.common.exceptions import ELFError
            from elftools.elf.elffile import ELFFile
        except ModuleNotFoundError as e:  # the extra servoctl[elf]
            raise extras.missing(e) from None
        try:
            f = open(path, "rb")
        except OSError as e:
            raise UsageError(f"--elf {path}: {e.strerror or e}") from None
        with f:
            try:
                table = ELFFile(f).get_section_by_name(".symtab")
            except ELFError:
                raise UsageError(f"--elf {path}: not an ELF file (give the build's .elf, not its .bin "
                                 "or a packed image)") from None
            if table is None:
                raise UsageError(f"--elf {path}: no symbol table (an ELF built with its symbols is needed)")
            self.functions = sorted((s["st_value"] & ~1, s["st_size"], s.name) for s in table.iter_symbols()
                                    if s["st_info"]["type"] == "STT_FUNC" and s["st_size"] > 0)
            marks = table.get_symbol_by_name("_board_mark") or []
        # The board the image is for: vector 7's mark, the address of the
        # linker's _board_mark (hal/ports/stm32_common/board_mark.h); None without it.
        mark = marks[0]["st_value"] if marks else None
        self.board = mark & 0xFFFF if mark is not None and mark >> 16 == BOARD_MARK_TAG else None

    def name(self, address: int):
        """"function+0xOFF" of the function holding address, or None."""
        address &= ~1
        for start, size, name in self.functions:
            if start <= address < start + size:
                return f"{name}+{address - start:#x}"
        return None
