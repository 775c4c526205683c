"""Skipping the main loop's awake passes that find nothing to do, at no
cost to what the simulated wire shows (docs/virtual-boards.md, "Skipping
an idle pass").

The application stays awake for 4 ms after every byte it hears
(docs/sleep.md), going round its main loop, and every instruction of it
would be emulated. Within one run of the core (up to the next event: a
byte's end on the bus, a SysTick wrap, a model's event, the slice's end)
nothing outside the CPU moves: the models step between runs, exceptions
are taken at a run's start, and SysTick's counter reads as it stood then.
A pass that leaves the CPU's registers and the SRAM's live bytes (the
static data, and the stack from SP up: below SP nothing is read before it
is written) as it found them, with no watched register stored to or read
on the way, is therefore a fixed point: every pass after it, to the run's
end, is the same pass again.

The instruction counter (native/instruction_count.c) looks where a pass
begins: servo_poll's first instruction, found by name in the
application's ELF, and only while the flash holds the ELF's code (its
whole code section: the static data's end is the ELF's too).
It compares each pass's start with the one before in the same run (at
most TRIES of them), and at the first match counts the whole passes left
in the run as run, at their measured length in instructions, without
running them; the part-pass the run ends in is emulated. The run ends at
the same instruction, in the same state, at the same cycle count as when
every pass is emulated: the answers leave at the same simulated times
(tests/vboard/test_idle_skip.py). VBOARD_SKIP=0, or a core's skip_idle
set false, emulates every pass.

What it takes on trust: the firmware does not read back a peripheral
register that no model watches (the watchdog's key, the PWM compares), so
such a store cannot make two passes differ."""
import ctypes
import os
import struct
from pathlib import Path

from unicorn import arm_const as arm
from unicorn.unicorn_py3.unicorn import uclib

PASS_START = "servo_poll"  # the main loop's pass begins with this call (firmware/boards/common/app_start.h)
TRIES = 3                  # passes compared in a run before it gives up until the next
STATE_REGS = tuple(getattr(arm, f"UC_ARM_REG_R{n}") for n in range(13)) + (
    arm.UC_ARM_REG_SP, arm.UC_ARM_REG_LR, arm.UC_ARM_REG_XPSR, arm.UC_ARM_REG_PRIMASK, arm.UC_ARM_REG_CONTROL)
SHT_SYMTAB, STT_FUNC = 2, 2


def _elf(path):
    """(file bytes, section headers) of a 32-bit little-endian ELF, or None."""
    try:
        data = Path(path).read_bytes()
    except OSError:
        return None
    if data[:6] != b"\x7fELF\x01\x01":
        return None
    shoff, = struct.unpack_from("<I", data, 0x20)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x2E)
    # (name, type, flags, addr, offset, size, link, info, addralign, entsize)
    return data, [struct.unpack_from("<10I", data, shoff + i * shentsize) for i in range(shnum)]


def _symbol(elf, name: str):
    """(value, size, type) of a symbol in the ELF's .symtab, or None."""
    data, sections = elf
    for sh in sections:
        if sh[1] != SHT_SYMTAB:
            continue
        strings = sections[sh[6]][4]
        for at in range(sh[4], sh[4] + sh[5], sh[9]):
            st_name, value, size, info = struct.unpack_from("<IIIB", data, at)
            begin = strings + st_name
            if data[begin:data.index(b"\0", begin)] == name.encode():
                return value, size, info & 0xF
    return None


def pass_facts(path):
    """(address of the pass's first function, (address, bytes) of the
    code section that holds it, end of the firmware's static data: _ebss,
    above it the stack) in the application's ELF, or None. The whole
    section, not the function's bytes alone: another image may hold the
    same function at the same address, its static data laid out anew."""
    elf = _elf(path)
    found = elf and _symbol(elf, PASS_START)
    ebss = elf and _symbol(elf, "_ebss")
    if not found or not ebss or found[2] != STT_FUNC:
        return None
    address, size = found[0] & ~1, found[1]
    for s in elf[1]:
        if s[1] == 1 and s[3] <= address and address + size <= s[3] + s[5]:  # PROGBITS
            return address, (s[3], elf[0][s[4]:s[4] + s[5]]), ebss[0]
    return None


class IdleSkip:
    """Mixed into Core: the native counter's pass fields (InstructionCount),
    set once a board knows where its pass begins, armed at every run."""

    def _init_skip(self) -> None:
        self.skip_idle = os.environ.get("VBOARD_SKIP", "1") != "0"  # off: every pass emulated (tests)
        self.skip_at = 0           # where a pass begins (0: unknown, nothing skipped)
        c = self.count
        c.reg_read = ctypes.cast(uclib.uc_reg_read, ctypes.c_void_p)
        for i, register in enumerate(STATE_REGS):
            c.reg_ids[i] = register

    def skip_memory(self, ram, base: int, static_end: int) -> None:
        """The SRAM (a ctypes array mapped at base) and the end of the
        static data in it: what a pass may leave as it found it."""
        c = self.count
        self._seen_ram = (ctypes.c_ubyte * len(ram))()
        c.ram, c.seen_ram = ctypes.cast(ram, ctypes.c_void_p), ctypes.cast(self._seen_ram, ctypes.c_void_p)
        c.ram_base, c.ram_size, c.static_end = base, len(ram), static_end

    @property
    def passes_skipped(self) -> int:
        return self.count.skipped

    def _arm_skip(self) -> None:
        """Before a run: compare up to TRIES passes' starts (not in a run
        that ends at a CPSIE I: that run is no whole pass)."""
        c = self.count
        on = self.skip_idle and self.skip_at and c.ram and not c.until_cpsie
        c.pass_at, c.tries, c.have_seen = (self.skip_at, TRIES, 0) if on else (0, 0, 0)
