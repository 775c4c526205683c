"""The embedded flash and its interface (RM0008 3.3, RM0360 3.2; the same
registers on both parts): unlocked by the two keys, programmed a half-word
at a time into erased cells, erased a page at a time. The CPU fetches its
code from this flash, so it stands still while a half-word programs or a
page erases, for the datasheets' longest times (DS5319 and DS9773, "Flash
memory characteristics": tPROG 70 us and 53.5 us, tERASE 40 ms); the
peripherals and the DMA go on meanwhile.

Errors as the interface reports them: a write to a cell not erased (other
than 0x0000) sets PGERR and programs nothing; a write while locked or
without PG programs nothing. The wait states must cover the clock (RM0008
3.3.3: 0 up to 24 MHz, 1 up to 48, 2 up to 72; RM0360 3.5.1: 0 up to 24,
1 up to 48): a CPU faster than its flash reads garbage, here a HardFault.

The contents live in a file (--state): each program and erase writes
through, so a power cut keeps exactly what was programmed.

Power cuts (the control port's cutprogram and cutflash): the power goes as
the Nth program step from now begins (the cell keeps what it held), or as
the Nth flash operation, program step or page erase, begins. An erase cut
short leaves its page partly erased: the reference manuals give the erase
sequence (RM0008 3.3.3, RM0360 3.2.2), not what a power loss in it leaves,
so the model takes what a reader finds hardest, a page neither erased nor
as it was: its first half erased, the rest as it held."""
import os

from .model import Model

KEY1, KEY2 = 0x45670123, 0xCDEF89AB


class Flash(Model):
    def __init__(self, board, periph, memory, base: int, size: int, page: int, path,
                 program_s: float, erase_s: float):
        super().__init__(board, periph)
        self.memory, self.base, self.size, self.page = memory, base, size, page
        self.program_s, self.erase_s = program_s, erase_s
        self.path = path
        self.keys_seen = 0
        self.fail_programs = self.fail_erases = 0
        self.erases = 0          # page erases, ever: the state's page_erases
        self.erase_began_s = 0.0  # when the last one began: the state's erase_began_ms
        self.stalled_s = 0.0     # the CPU's stalls for them and for program steps
        self.cut_after_programs = 0  # the power goes as the Nth program step from now begins
        self.cut_after_ops = 0   # ... as the Nth operation, program step or erase, begins
        self.ops = 0             # program steps and erases begun, ever: the state's flash_ops
        self.fd = None
        self.blank = True
        if path is not None:
            self._open(path)
        self.i_acr, self.LATENCY = self.i["ACR"], self.bit("ACR", "LATENCY")
        self.watch("KEYR", self._keyr)
        self.watch("CR", self._cr)
        self.watch("SR", self._sr)
        self.core.on_write_range(base, base + size, self._store)

    def _open(self, path) -> None:
        fresh = not os.path.exists(path) or os.path.getsize(path) != self.size
        self.fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        if fresh:
            self.blank = True
            os.ftruncate(self.fd, 0)
            os.write(self.fd, bytes(self.memory.read(0, self.size)))
        else:
            self.blank = False
            self.memory.write(0, os.pread(self.fd, self.size, 0))

    def persist(self, offset: int, length: int) -> None:
        if self.fd is not None:
            os.pwrite(self.fd, bytes(self.memory.read(offset, length)), offset)

    def reset(self) -> None:
        super().reset()
        self.keys_seen = 0

    def check_wait_states(self, hz: int) -> bool:
        latency = self.w[self.i_acr] & self.LATENCY
        return hz <= 24_000_000 * (latency + 1)

    def _flag(self, name: str) -> int:
        fields = self.p.registers["SR"][2]
        return self.bit("SR", name if name in fields else {"WRPRTERR": "WRPRT"}[name])

    def _keyr(self, value, old, size):
        if self.keys_seen == 0 and value == KEY1:
            self.keys_seen = 1
        elif self.keys_seen == 1 and value == KEY2:
            self.keys_seen = 2
            self.put("CR", self.get("CR") & ~self.bit("CR", "LOCK"))
        else:
            self.keys_seen = 3  # a wrong key locks it until reset (RM0008 3.3.1)
        self.core.fix(self.addr("KEYR"), 0)

    def _cr(self, value, old, size):
        if value & self.bit("CR", "LOCK") and self.keys_seen == 2:
            self.keys_seen = 0  # locked again: the keys open it again
        locked = old & self.bit("CR", "LOCK")
        if locked:
            value = old | (value & self.bit("CR", "LOCK"))
        elif value & self.bit("CR", "STRT") and value & self.bit("CR", "PER"):
            self._erase(self.get("AR"))
            value &= ~self.bit("CR", "STRT")
        self.core.fix(self.addr("CR"), value)

    def _sr(self, value, old, size):
        clear = value & (self._flag("EOP") | self._flag("PGERR") | self._flag("WRPRTERR"))
        self.core.fix(self.addr("SR"), old & ~clear)

    def cut(self, program: bool) -> bool:
        """An operation begins: counted; True if the power goes in it."""
        self.ops += 1
        cut = False
        if program and self.cut_after_programs:
            self.cut_after_programs -= 1
            cut = self.cut_after_programs == 0
        if self.cut_after_ops:
            self.cut_after_ops -= 1
            cut = cut or self.cut_after_ops == 0
        return cut

    def cut_erase(self, start: int) -> None:
        """The power goes as the page at start erases: its first half erased."""
        self.memory.write(start, b"\xff" * (self.page // 2))
        self.persist(start, self.page // 2)
        self.core.stop(reset="power")

    def _erase(self, address: int) -> None:
        start = (address - self.base) // self.page * self.page
        if 0 <= start < self.size and self.cut(program=False):
            self.erases += 1
            self.erase_began_s = self.core.now_s()
            self.cut_erase(start)
            return
        if 0 <= start < self.size and self.fail_erases == 0:
            self.memory.write(start, b"\xff" * self.page)
            self.persist(start, self.page)
            self.put("SR", self.get("SR") | self._flag("EOP"))
        else:
            self.fail_erases = max(0, self.fail_erases - 1)
            self.put("SR", self.get("SR") | self._flag("PGERR"))
        self.erases += 1
        self.erase_began_s = self.core.now_s()
        self.stalled_s += self.erase_s
        self.core.stop(stall_s=self.erase_s)

    def _store(self, address: int, value: int, size: int) -> None:
        """A store into flash: a program step when PG is set, else nothing
        (the cells keep what they hold either way, set right after it)."""
        offset = address - self.base
        old = bytes(self.memory.read(offset, size))
        cr = self.get("CR")
        programmed = old
        if not cr & self.bit("CR", "LOCK") and cr & self.bit("CR", "PG"):
            if self.cut(program=True):  # the cell keeps what it held
                self.core.fix(address, old)
                self.core.stop(reset="power")
                return
            new = value.to_bytes(size, "little")
            cells = []
            for i in range(0, size, 2):
                was = int.from_bytes(old[i:i + 2], "little")
                want = int.from_bytes(new[i:i + 2], "little")
                if (was != 0xFFFF and want != 0) or self.fail_programs:
                    self.fail_programs = max(0, self.fail_programs - 1)
                    self.put("SR", self.get("SR") | self._flag("PGERR"))
                    cells.append(old[i:i + 2])
                else:
                    cells.append(want.to_bytes(2, "little"))
                    self.put("SR", self.get("SR") | self._flag("EOP"))
            programmed = b"".join(cells)
            self.stalled_s += self.program_s * max(1, size // 2)
            self.core.stop(stall_s=self.program_s * max(1, size // 2))
        self.memory.write(offset, programmed)
        self.persist(offset, size)
        self.core.fix(address, programmed)
