"""A Cortex-M core on Unicorn, with what ARM puts beside it in the system
control space: SysTick, the NVIC and the SCB registers the firmware uses.

Time is the CPU's: each instruction costs the board's cycles per
instruction (its cycle model, docs/benchmark.md), counted as it runs (a
code hook in C, native/instruction_count.c), and peripherals move on
between runs of at most a slice. A WFI ends the run and the core sleeps
(B1.5.19): time then passes without running code until an enabled
exception is pending, which wakes it whatever PRIMASK says; with PRIMASK
set, a CPSIE I right after the WFI is carried out here and the exception
taken. Whenever PRIMASK holds back a pending exception, awake or after a
wake, the run ends at the CPSIE I that clears it: the exception is taken
right after that instruction, as on silicon, not at the slice's end.
The main loop's awake passes that find nothing to do are counted as run
without running them (idle_skip.py), with the same result.

Its memory and register writes are memory.py's (MemoryMap), its
exceptions exceptions.py's (Exceptions), which exception a fault is and
the M3's fault status registers faults.py's (Faults), the M3's MPU
mpu.py's (Mpu), the system control space's registers system_space.py's."""
import ctypes
import math
import os
import sys

from unicorn import UC_ARCH_ARM, UC_HOOK_CODE, UC_HOOK_INTR, UC_HOOK_MEM_UNMAPPED, UC_MODE_MCLASS, UC_MODE_THUMB
from unicorn import UC_ERR_FETCH_UNMAPPED, UC_ERR_INSN_INVALID, Uc, UcError
from unicorn import arm_const as arm
from unicorn.unicorn_py3.unicorn import uclib

from .exceptions import Exceptions
from .faults import Faults
from .mpu import Mpu
from .idle_skip import STATE_REGS, IdleSkip
from .memory import MemoryMap
from .native import lib as native_lib
from .system_space import (NVIC_ICER, NVIC_ICPR, NVIC_ISER, NVIC_ISPR, SCB_AIRCR, SCB_ICSR, SYST_CSR, SYST_CVR,
                           SystemControlSpace)

CORE_REGS = tuple(getattr(arm, f"UC_ARM_REG_R{n}") for n in range(13)) + (arm.UC_ARM_REG_SP, arm.UC_ARM_REG_LR)
WFI, CPSIE_I = 0xBF30, 0xB662


class InstructionCount(ctypes.Structure):
    """native/instruction_count.c's struct vboard_count."""
    _fields_ = [("executed", ctypes.c_uint64), ("limit", ctypes.c_uint64), ("stop", ctypes.c_void_p),
                ("read", ctypes.c_void_p), ("until_cpsie", ctypes.c_uint32), ("at_cpsie", ctypes.c_uint32),
                ("pass_at", ctypes.c_uint32), ("tries", ctypes.c_uint32), ("reg_read", ctypes.c_void_p),
                ("reg_ids", ctypes.c_int32 * len(STATE_REGS)), ("ram", ctypes.c_void_p), ("seen_ram", ctypes.c_void_p),
                ("ram_base", ctypes.c_uint32), ("ram_size", ctypes.c_uint32), ("static_end", ctypes.c_uint32),
                ("hooks", ctypes.c_uint32), ("skipped", ctypes.c_uint64), ("have_seen", ctypes.c_uint32),
                ("seen_hooks", ctypes.c_uint32), ("seen_live", ctypes.c_uint32),
                ("seen_regs", ctypes.c_uint32 * len(STATE_REGS)), ("seen_at", ctypes.c_uint64)]


def plain_store_size(hw: int, hw2: int) -> tuple:
    """(size, writeback) of a single store at this Thumb instruction: its
    size (2 or 4, 0 for any other instruction) and, for STR/STRB/STRH with
    an 8-bit offset and writeback (ARMv7-M A7.7.158 T4, the compiler's
    `str.w r6, [r0], #4`), (Rn, what it adds to Rn), else None."""
    if hw >> 11 in (0x0C, 0x0E, 0x10, 0x12) or hw >> 9 in (0x28, 0x29, 0x2A):
        return 2, None  # STR/STRB/STRH immediate, STR SP-relative, STR/STRH/STRB register
    if hw & 0xFFF0 in (0xF8C0, 0xF880, 0xF8A0):
        return 4, None  # STR/STRB/STRH imm12
    if hw & 0xFFF0 in (0xF840, 0xF800, 0xF820):
        if hw2 & 0x0FC0 == 0:
            return 4, None  # register offset
        if hw2 & 0x0800 and hw2 & 0x0400 and not hw2 & 0x0100:
            return 4, None  # offset, no writeback
        if hw2 & 0x0800 and hw2 & 0x0100:  # pre- or post-indexed, writeback
            imm8 = hw2 & 0xFF
            return 4, (hw & 0xF, imm8 if hw2 & 0x0200 else -imm8)
    return 0, None


class Stop(Exception):
    """Raised by run() when the board must reset (cause in .args[0])."""


class Core(MemoryMap, Exceptions, Faults, Mpu, SystemControlSpace, IdleSkip):
    def __init__(self, cpu_model: int, hz: int, cpi: float, has_vtor: bool, irq_words: int):
        self.uc = Uc(UC_ARCH_ARM, UC_MODE_THUMB | UC_MODE_MCLASS)
        self.uc.ctl_set_cpu_model(cpu_model)
        self.hz, self.cpi, self.has_vtor, self.irq_words = hz, cpi, has_vtor, irq_words
        self.v7m = cpu_model != arm.UC_CPU_ARM_CORTEX_M0  # ARMv7-M: configurable faults, MPU
        self.cycles = 0.0            # HCLK cycles since power-up (SysTick counts these)
        self.time_s = 0.0            # since power-up
        self.handlers = {}           # register address -> handler(value, old, size)
        self.ranges = []             # (begin, end, handler(address, value, size))
        self._write_hooks = []       # installed by _hook_writes
        self._hooks_stale = True
        self.fixes = []              # (address, bytes) the registers read once the store has landed
        self.late_fixes = []         # ... after the next slice (a store that runs again)
        self.stall_s = 0.0           # the CPU stands still this long, peripherals do not
        self.reset_cause = None
        self._stopping = None        # the address whose store stopped the CPU
        self._passthrough = None     # ... and runs again without its handler
        self._stop_pc = None
        self.locked_up = False
        self.fault = None
        self.deferred = []           # what may not happen inside Unicorn (remapping memory)
        self.enabled = set()         # IRQ numbers
        self.pending = set()         # exception numbers
        self.active = []             # (exception, priority) of the handlers running, innermost last
        self.systick_base = 0.0      # cycle at which the counter last loaded
        self.regions = []            # (base, end, memoryview) of memory mapped from the host
        self._pages = {}             # 1 KB page -> (base, view): _region's cache
        self._words = {}             # region base -> its memory as 32-bit words
        self.on_write(SYST_CSR, self._syst_csr)
        self.on_write(SYST_CVR, self._syst_cvr)
        self.on_write(SCB_ICSR, self._icsr)
        self.on_write(SCB_AIRCR, self._aircr)
        for w in range(irq_words):
            self.on_write(NVIC_ISER + 4 * w, self._nvic(w, enable=True))
            self.on_write(NVIC_ICER + 4 * w, self._nvic(w, enable=False))
            self.on_write(NVIC_ISPR + 4 * w, self._nvic_pend(w, True))
            self.on_write(NVIC_ICPR + 4 * w, self._nvic_pend(w, False))
        self.uc.hook_add(UC_HOOK_INTR, self._interrupt)
        self.uc.hook_add(UC_HOOK_MEM_UNMAPPED, self._unmapped)
        self.unmapped_at = None      # the address of the last access to nothing
        self.fault_pending = None    # (why, kind) of a fault an interrupt hook reported
        self.spin_at = 0             # thread mode spins here (a hung main loop: run.py's inject hang)
        self._init_faults()
        self._init_mpu()
        self._uch = self.uc._uch
        self._regbuf = ctypes.c_uint32()
        self._regbuf_ref = ctypes.byref(self._regbuf)
        self._batches = {}
        self.running = False         # inside emu_start
        self.ran = False             # the last run() ran code (else it slept or was locked up)
        self.asleep = False          # after a WFI, until an exception is pending
        self.taken = {}              # exception number -> how many times it was taken
        self.lines = {}              # exception number -> its level-sensitive line (assert_irq)
        self.slept_s = 0.0           # time spent asleep since power-up
        self.count = InstructionCount(0, 0, ctypes.cast(uclib.uc_emu_stop, ctypes.c_void_p),
                                      ctypes.cast(uclib.uc_mem_read, ctypes.c_void_p), 0, 0)
        self._count_hook = ctypes.c_size_t()
        counter = ctypes.cast(native_lib().vboard_count_instruction, ctypes.c_void_p)
        if uclib.uc_hook_add(self.uc._uch, ctypes.byref(self._count_hook), UC_HOOK_CODE, counter,
                             ctypes.addressof(self.count), 1, 0):
            raise RuntimeError("Unicorn refused the instruction counter")
        self._init_skip()

    # ---- registers: Unicorn's C API directly (its Python wrapper costs more
    # than the call, and exceptions touch a dozen registers) ----------------
    def reg(self, register: int) -> int:
        uclib.uc_reg_read(self._uch, register, self._regbuf_ref)
        return self._regbuf.value

    def set_reg(self, register: int, value: int) -> None:
        self._regbuf.value = value & 0xFFFFFFFF
        uclib.uc_reg_write(self._uch, register, self._regbuf_ref)

    def _batch(self, registers: tuple):
        batch = self._batches.get(registers)
        if batch is None:
            values = (ctypes.c_uint32 * len(registers))()
            pointers = (ctypes.c_void_p * len(registers))(
                *[ctypes.addressof(values) + 4 * i for i in range(len(registers))])
            batch = self._batches[registers] = ((ctypes.c_int32 * len(registers))(*registers), pointers, values)
        return batch

    def regs(self, registers: tuple) -> list:
        """Several registers in one call."""
        ids, pointers, values = self._batch(registers)
        uclib.uc_reg_read_batch(self._uch, ids, pointers, len(registers))
        return list(values)

    def set_regs(self, registers: tuple, new_values) -> None:
        ids, pointers, values = self._batch(registers)
        for i, v in enumerate(new_values):
            values[i] = v & 0xFFFFFFFF
        uclib.uc_reg_write_batch(self._uch, ids, pointers, len(registers))

    # ---- time -------------------------------------------------------------
    def now_s(self) -> float:
        return self.time_s

    def run(self, max_s: float) -> float:
        """Runs the CPU for at most max_s of its time; returns the time that
        passed (a stall included). Raises Stop when the board must reset."""
        if self.locked_up:
            self.idle(max_s)
            self.cycles += max_s * self.hz
            return max_s
        # Up to the first instruction that ends at or past max_s: a run that
        # stopped short of an event by a part of an instruction would need
        # another run of its own to get there.
        count = max(1, math.ceil(max_s * self.hz / self.cpi - 1e-6))
        self.ran = False
        if self.asleep:
            if not self.wake_pending():
                return self._sleep(max_s)
            self.asleep = False
            if self.reg(arm.UC_ARM_REG_PRIMASK) & 1:
                pc = self.reg(arm.UC_ARM_REG_PC)
                if self.rd16(pc & ~1) == CPSIE_I:  # the usual WFI; CPSIE: run it here, one run less
                    self.set_reg(arm.UC_ARM_REG_PRIMASK, 0)
                    self.set_reg(arm.UC_ARM_REG_PC, (pc + 2) | 1)
                    self.cycles += self.cpi
                    self.time_s += self.cpi / self.hz
        if self._hooks_stale:
            self._hook_writes()
        self._take_exception()
        self._update_systick()
        pc = self.reg(arm.UC_ARM_REG_PC) | 1
        if self.spin_at and pc == self.spin_at | 1 and not self.reg(arm.UC_ARM_REG_IPSR) & 0x1FF:
            return self._spin(max_s)
        self.count.executed, self.count.limit = 0, count
        # Masked with an exception waiting: it is taken right after the
        # CPSIE I, so the run ends before that (native/instruction_count.c).
        masked = self.pending and self.reg(arm.UC_ARM_REG_PRIMASK) & 1
        self.count.until_cpsie = bool(masked and self.wake_pending())
        self._arm_skip()
        self.count.at_cpsie = 0
        faulted = False
        self.running = self.ran = True
        try:
            self.uc.emu_start(pc, 0xFFFFFFFF)
        except UcError as e:
            faulted = True
            if os.environ.get("VBOARD_TRACE"):
                r = {n: hex(self.uc.reg_read(getattr(arm, "UC_ARM_REG_" + n))) for n in ("PC", "LR", "SP", "IPSR", "XPSR")}
                print(f"vboard: fault {e} at {self.time_s:.4f} s: {r}", file=sys.stderr, flush=True)
            self._fault(str(e), *self._fault_kind(e))
        if self.fault_pending is not None:
            faulted = True
            (why, kind), self.fault_pending = self.fault_pending, None
            self._fault(why, kind)
        self.running = False
        executed = self.count.executed
        if self.count.at_cpsie and not faulted:  # carried out here; the exception is taken next run
            self.set_reg(arm.UC_ARM_REG_PRIMASK, 0)
            self.set_reg(arm.UC_ARM_REG_PC, (self.reg(arm.UC_ARM_REG_PC) + 2) | 1)
            executed += 1
        ran = executed * self.cpi
        if executed < count and not (faulted or self.fixes or self.stall_s or self.reset_cause or self.deferred
                                     or self.count.at_cpsie):
            self.asleep = self._after_wfi()
        for action in self.deferred:
            action()
        self.deferred = []
        for address, data in self.late_fixes:
            self.write(address, data)
        self.late_fixes = []
        if self._stopping is not None:
            pc = self.reg(arm.UC_ARM_REG_PC)
            xpsr = self.reg(arm.UC_ARM_REG_XPSR)
            in_it_block = (xpsr >> 10) & 0x3F or (xpsr >> 25) & 3  # ITSTATE (B1.4.2)
            size, writeback = (0, None) if in_it_block else plain_store_size(self.rd16(pc & ~1),
                                                                               self.rd16((pc & ~1) + 2))
            if pc != self._stop_pc:  # the store completed and the CPU moved on
                for address, data in self.fixes:
                    self.write(address, data)
            elif size:
                for address, data in self.fixes:
                    self.write(address, data)
                if writeback:
                    rn = CORE_REGS[writeback[0]]
                    self.set_reg(rn, self.reg(rn) + writeback[1])
                self.set_reg(arm.UC_ARM_REG_PC, (pc + size) | 1)
            else:
                self._passthrough = self._stopping
                self.late_fixes = self.fixes
            self._stopping, self.fixes = None, []
        else:
            for address, data in self.fixes:  # from a passed-over store
                self.write(address, data)
            self.fixes = []
        cycles = ran + self.stall_s * self.hz
        passed = cycles / self.hz
        self.stall_s = 0.0
        self.cycles += cycles
        self.time_s += passed
        self._systick_after(cycles)
        if self.reset_cause:
            cause, self.reset_cause = self.reset_cause, None
            raise Stop(cause)
        if self.asleep and passed < max_s and not self.wake_pending():
            passed += self._sleep(max_s - passed)  # the rest of the slice: one call, not two
        return passed

    def _unmapped(self, uc, access, address, size, value, data):
        self.unmapped_at = address
        return False

    def _fault_kind(self, e: UcError) -> tuple:
        """(kind, address) of the fault an error of Unicorn's is: nothing
        there to fetch from, an instruction it cannot decode, or a data
        access to nothing (a precise bus error, BFAR its address)."""
        address, self.unmapped_at = self.unmapped_at, None
        if e.errno == UC_ERR_FETCH_UNMAPPED:
            return "bus_fetch", None
        if e.errno == UC_ERR_INSN_INVALID:
            return "undef", None
        return "bus_data", address

    def _spin(self, max_s: float) -> float:
        """A hung main loop: thread mode goes round one instruction, awake,
        until an exception is taken (at the next run's start)."""
        cycles = max_s * self.hz
        self.cycles += cycles
        self.time_s += max_s
        self._systick_after(cycles)
        return max_s

    def _after_wfi(self) -> bool:
        """Whether a run that ended early ended on a WFI (Unicorn stops
        there, the PC past it), not on a hook's stop or a fault."""
        pc = self.reg(arm.UC_ARM_REG_PC) & ~1
        try:
            return self.rd16(pc - 2) == WFI
        except (KeyError, UcError):
            if os.environ.get("VBOARD_TRACE"):
                print(f"vboard: a run ended early at {pc:#010x}", file=sys.stderr, flush=True)
            return False

    def _sleep(self, seconds: float) -> float:
        """Asleep: the clocks run, the code does not."""
        cycles = seconds * self.hz
        self.cycles += cycles
        self.time_s += seconds
        self.slept_s += seconds
        self._systick_after(cycles)
        return seconds

    def idle(self, seconds: float) -> None:
        """Time passes with the CPU held (in reset, or powered off)."""
        self.time_s += seconds

