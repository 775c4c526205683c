"""A Cortex-M core on Unicorn, with what ARM puts beside it in the system
control space: SysTick, the NVIC and the SCB registers the firmware uses.

Unicorn runs the Thumb code; it has no NVIC, so exceptions are entered and
left here as the architecture says (ARMv7-M ARM B1.5.6, ARMv6-M ARM B1.5.6):
entry pushes r0-r3, r12, lr, pc and xPSR on the main stack (8-byte aligned,
bit 9 of the stacked xPSR saying so), sets IPSR and LR = EXC_RETURN and
jumps through the vector table; the handler's return to EXC_RETURN reaches
Unicorn as interrupt 8 (QEMU's EXCP_EXCEPTION_EXIT), and the frame is popped
here. Priorities come from the NVIC's IPR bytes and the SCB's SHPR3 for
SysTick (B3.2.11, B3.4): a pending, enabled exception is taken when PRIMASK
is clear and its priority is higher (a lower number) than the running
handler's, which it then preempts (EXC_RETURN to handler mode); at equal
priority the lower exception number goes first (B1.5.4). HardFault's is -1.

Time is the CPU's: each instruction costs the board's cycles per
instruction (its cycle model, docs/benchmark.md), counted as it runs (a
code hook in C, native/instruction_count.c), and peripherals move on
between runs of at most a slice. A WFI ends the run and the core sleeps
(B1.5.19): time then passes without running code until an enabled
exception is pending, which wakes it whatever PRIMASK says; with PRIMASK
set, a CPSIE I right after the WFI is carried out here and the exception
taken, or else a few instructions run before it is.

Peripheral registers are RAM to the CPU, so reading them costs no Python;
writes call the peripheral's handler before the value lands. A handler that
makes the register read other than what was written (a write-1-to-clear
flag, a ready bit) or that stalls or resets the CPU stops it after the
store; the register then takes its value before the next instruction runs.
The CPU resumes after the store (a plain STR/STRH/STRB, which is what the
compiler makes of a register write), or, for any other store instruction
and for any store inside an IT block (whose state a jump over it would
break), runs it again, that second time past the handler, and the register
takes its value at the end of that slice."""
import ctypes
import os
import struct
import sys

from unicorn import UC_ARCH_ARM, UC_HOOK_CODE, UC_HOOK_INTR, UC_HOOK_MEM_WRITE, UC_MODE_MCLASS, UC_MODE_THUMB
from unicorn import Uc, UcError
from unicorn import arm_const as arm
from unicorn.unicorn_py3.unicorn import uclib

from .native import lib as native_lib
from .system_space import (FIRST_IRQ, SCS_BASE, ICSR_PENDSTSET, NVIC_ICER, NVIC_ICPR, NVIC_IPR, NVIC_ISER, NVIC_ISPR,
                           SCB_AIRCR, SCB_ICSR, SCB_SHPR3, SCB_VTOR, SYST_CSR, SYST_CVR, SYSTICK,
                           SystemControlSpace)

EXC_RETURN_THREAD_MSP = 0xFFFFFFF9
EXCP_EXCEPTION_EXIT = 8  # QEMU's, as Unicorn reports it
HARD_FAULT = 3
FRAME_REGS = (arm.UC_ARM_REG_R0, arm.UC_ARM_REG_R1, arm.UC_ARM_REG_R2, arm.UC_ARM_REG_R3,
              arm.UC_ARM_REG_R12, arm.UC_ARM_REG_LR)
ENTRY_READ = FRAME_REGS + (arm.UC_ARM_REG_SP, arm.UC_ARM_REG_XPSR, arm.UC_ARM_REG_PC)
ENTRY_WRITE = (arm.UC_ARM_REG_SP, arm.UC_ARM_REG_LR, arm.UC_ARM_REG_IPSR, arm.UC_ARM_REG_PC)
EXIT_WRITE = FRAME_REGS + (arm.UC_ARM_REG_SP, arm.UC_ARM_REG_XPSR, arm.UC_ARM_REG_IPSR, arm.UC_ARM_REG_PC)

EXC_RETURN_HANDLER = 0xFFFFFFF1
CORE_REGS = tuple(getattr(arm, f"UC_ARM_REG_R{n}") for n in range(13)) + (arm.UC_ARM_REG_SP, arm.UC_ARM_REG_LR)
WFI, CPSIE_I = 0xBF30, 0xB662
WAKE_RUN = 16  # instructions run after a wake with PRIMASK set before the exception is taken


class InstructionCount(ctypes.Structure):
    """native/instruction_count.c's struct vboard_count."""
    _fields_ = [("executed", ctypes.c_uint64), ("limit", ctypes.c_uint64), ("stop", ctypes.c_void_p)]


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


class Core(SystemControlSpace):
    def __init__(self, cpu_model: int, hz: int, cpi: float, has_vtor: bool, irq_words: int):
        self.uc = Uc(UC_ARCH_ARM, UC_MODE_THUMB | UC_MODE_MCLASS)
        self.uc.ctl_set_cpu_model(cpu_model)
        self.hz, self.cpi, self.has_vtor, self.irq_words = hz, cpi, has_vtor, irq_words
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
        self.count = InstructionCount(0, 0, ctypes.cast(uclib.uc_emu_stop, ctypes.c_void_p))
        self._count_hook = ctypes.c_size_t()
        counter = ctypes.cast(native_lib().vboard_count_instruction, ctypes.c_void_p)
        if uclib.uc_hook_add(self.uc._uch, ctypes.byref(self._count_hook), UC_HOOK_CODE, counter,
                             ctypes.addressof(self.count), 1, 0):
            raise RuntimeError("Unicorn refused the instruction counter")

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

    # ---- memory ---------------------------------------------------------
    def map_host(self, base: int, size: int, buf=None):
        """Maps host memory at base (a new zeroed buffer unless given): the
        models read and write it directly, without going through Unicorn."""
        if buf is None:
            buf = (ctypes.c_ubyte * size)()
        self.uc.mem_map_ptr(base, size, 7, ctypes.addressof(buf))
        view = memoryview(buf).cast("B")
        self.regions.append((base, base + size, view))
        self._words[base] = view.cast("I")
        self._pages = {}
        return buf

    def words(self, address: int):
        """(address's host-mapped region as 32-bit words, its word's index)."""
        base, _ = self._region(address)
        return self._words[base], (address - base) // 4

    def map_system_control_space(self) -> None:
        """SysTick, the NVIC and the SCB, mapped after the board's memory:
        Unicorn 2.1 gives a host-memory block mapped after a smaller one the
        offset of the block before it in its RAM list, so with this 4 KB
        block first the flash and the SRAM shared offsets, and every store
        to the stack over the bytes of the hot code in flash threw its
        translation away (the F103's control tick ran 4 to 10 times slower).
        Mapped last, no two blocks share an offset (both boards' layouts,
        checked store by store)."""
        self.map_host(SCS_BASE, 0x1000)
        self.scs = self._words[SCS_BASE]

    def _region(self, address: int):
        """(base, view) of the host-mapped region holding address, by its
        1 KB page (the models touch a few pages very often), or None."""
        page = address >> 10
        hit = self._pages.get(page)
        if hit is None:
            hit = next(((base, view) for base, end, view in self.regions if base <= address < end), None)
            if hit is not None:
                self._pages[page] = hit
        return hit

    def view(self, address: int):
        """(address's host-mapped region as bytes, address's offset in it)."""
        hit = self._region(address)
        if hit is None:
            raise KeyError(f"{address:#010x} is not host-mapped")
        return hit[1], address - hit[0]

    def on_write(self, address: int, handler) -> None:
        """Stores into the register (word) at address go to
        handler(value, old, size) before they land."""
        self.handlers[address] = handler
        self._hooks_stale = True

    def on_write_range(self, begin: int, end: int, handler) -> None:
        """Stores into [begin, end) (memory, not registers) go to
        handler(address, value, size) before they land."""
        self.ranges.append((begin, end, handler))
        self._hooks_stale = True

    def _hook_writes(self) -> None:
        """One write hook per peripheral block (1 KB) from its first
        handled register to its last, and one per memory range: Unicorn
        runs a store that a write hook watches outside the IT block it is in
        (the block's state is lost), so stores to a peripheral without
        handlers (the PWM compares, set under IT) are not watched at all;
        and few hooks keep every other store cheap."""
        for h in self._write_hooks:
            self.uc.hook_del(h)
        blocks = {}
        for address in self.handlers:
            lo, hi = blocks.get(address >> 10, (address, address))
            blocks[address >> 10] = (min(lo, address), max(hi, address))
        spans = [(lo, hi + 3) for lo, hi in blocks.values()] + [(b, e - 1) for b, e, _ in self.ranges]
        self._write_hooks = [self.uc.hook_add(UC_HOOK_MEM_WRITE, self._write_hook, begin=b, end=e)
                             for b, e in spans]
        self._hooks_stale = False

    def _read(self, address: int, fmt: str) -> int:
        hit = self._region(address)
        if hit is not None:
            return struct.unpack_from(fmt, hit[1], address - hit[0])[0]
        return struct.unpack(fmt, self.uc.mem_read(address, struct.calcsize(fmt)))[0]  # an alias (address 0)

    def rd32(self, address: int) -> int:
        return self._read(address, "<I")

    def rd16(self, address: int) -> int:
        return self._read(address, "<H")

    def rd_bytes(self, address: int, size: int) -> int:
        return self._read(address, {1: "<B", 2: "<H", 4: "<I"}[size])

    def wr32(self, address: int, value: int) -> None:
        view, at = self.view(address)
        struct.pack_into("<I", view, at, value & 0xFFFFFFFF)

    def write(self, address: int, data: bytes) -> None:
        view, at = self.view(address)
        view[at:at + len(data)] = data

    def fix(self, address: int, value, size: int = 4) -> None:
        """The register (or memory) reads value (an int of size bytes, or
        bytes) from the instruction after the current store on."""
        data = value if isinstance(value, bytes) else (value & ((1 << 8 * size) - 1)).to_bytes(size, "little")
        self.fixes.append((address, data))
        self.uc.emu_stop()

    def defer(self, action) -> None:
        """From a handler: action() runs once the CPU has stopped after this
        store (before the next instruction)."""
        self.deferred.append(action)
        self.uc.emu_stop()

    def new_event(self) -> None:
        """From a handler: the peripheral acts sooner than this run would end
        (a byte shifting out): the CPU stops after this store."""
        if self.running:
            self.defer(lambda: None)

    def stop(self, stall_s: float = 0.0, reset: str = None) -> None:
        """From a handler: the CPU stops after this store, stalled for
        stall_s, or resets."""
        self.stall_s += stall_s
        if reset:
            self.reset_cause = reset
        self.uc.emu_stop()

    def _write_hook(self, uc, access, address, size, value, data):
        if self._passthrough == address:
            self._passthrough = None
            return
        word = address & ~3
        handler = self.handlers.get(word)
        if handler is None:
            for begin, end, memory_handler in self.ranges:
                if begin <= address < end:
                    memory_handler(address, value, size)
                    if self.fixes or self.stall_s or self.reset_cause or self.deferred:
                        self._stopping = address
                        self._stop_pc = self.reg(arm.UC_ARM_REG_PC)
            return
        shift = 8 * (address & 3)
        old = self.rd32(word)
        if size < 4:  # a byte or half-word store into a word register
            mask = ((1 << (8 * size)) - 1) << shift
            value = (old & ~mask) | ((value << shift) & mask)
        handler(value & 0xFFFFFFFF, old, size)
        if self.fixes or self.stall_s or self.reset_cause or self.deferred:
            self._stopping = address
            self._stop_pc = self.reg(arm.UC_ARM_REG_PC)

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
        count = max(1, int(max_s * self.hz / self.cpi))
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
                else:
                    count = min(count, WAKE_RUN)
        if self._hooks_stale:
            self._hook_writes()
        self._take_exception()
        self._update_systick()
        pc = self.reg(arm.UC_ARM_REG_PC) | 1
        self.count.executed, self.count.limit = 0, count
        faulted = False
        self.running = self.ran = True
        try:
            self.uc.emu_start(pc, 0xFFFFFFFF)
        except UcError as e:
            faulted = True
            if os.environ.get("VBOARD_TRACE"):
                r = {n: hex(self.uc.reg_read(getattr(arm, "UC_ARM_REG_" + n))) for n in ("PC", "LR", "SP", "IPSR", "XPSR")}
                print(f"vboard: fault {e} at {self.time_s:.4f} s: {r}", file=sys.stderr, flush=True)
            self._fault(str(e))
        self.running = False
        executed = self.count.executed
        ran = executed * self.cpi
        if executed < count and not (faulted or self.fixes or self.stall_s or self.reset_cause or self.deferred):
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

    def wake_pending(self) -> bool:
        """An exception that ends a WFI: pending and enabled (B1.5.19)."""
        return any(e < FIRST_IRQ or (e - FIRST_IRQ) in self.enabled for e in self.pending)

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

    # ---- exceptions -------------------------------------------------------
    def raise_irq(self, irq: int) -> None:
        self.pending.add(FIRST_IRQ + irq)

    def assert_irq(self, irq: int, line) -> None:
        """A level-sensitive line (line() says whether it is high): pending
        now unless its handler is running; a handler that returns with the
        line still high has it pending again (B1.5.4), one that cleared it
        does not run twice."""
        self.lines[FIRST_IRQ + irq] = line
        if not any(e == FIRST_IRQ + irq for e, _ in self.active):
            self.pending.add(FIRST_IRQ + irq)

    def _fault(self, why: str) -> None:
        """A bus fault or undefined instruction: HardFault, as on silicon
        (the firmware's handler then spins until the watchdog resets). A
        fault that cannot be taken (the stack pointer is not in RAM) locks
        the core up (ARMv7-M ARM B1.5.15): it runs nothing until a reset."""
        self.fault = why
        self.pending.add(HARD_FAULT)
        try:
            self._take_exception(force=True)
        except KeyError:
            self.locked_up = True

    def priority(self, exc: int) -> int:
        if exc == HARD_FAULT:
            return -1
        if exc == SYSTICK:
            return self.rd32(SCB_SHPR3) >> 24
        if exc >= FIRST_IRQ:
            irq = exc - FIRST_IRQ
            return self.rd32(NVIC_IPR + (irq & ~3)) >> (8 * (irq & 3)) & 0xFF
        return 0

    def _take_exception(self, force: bool = False) -> None:
        if not self.pending:
            return
        if self.reg(arm.UC_ARM_REG_PRIMASK) & 1 and not force:
            return
        running = self.active[-1][1] if self.active else 256
        ready = sorted((self.priority(e), e) for e in self.pending
                       if e < FIRST_IRQ or (e - FIRST_IRQ) in self.enabled)
        if not ready or (ready[0][0] >= running and not force):
            return
        prio, exc = ready[0]
        self.pending.discard(exc)
        self.taken[exc] = self.taken.get(exc, 0) + 1
        nested = bool(self.active)
        self.active.append((exc, prio))
        if exc == SYSTICK:
            self.wr32(SCB_ICSR, self.rd32(SCB_ICSR) & ~ICSR_PENDSTSET)
        *stacked, sp, xpsr, pc = self.regs(ENTRY_READ)
        realign = sp & 4
        sp = (sp - 32) & ~7
        frame = stacked + [pc & ~1, (xpsr | (1 << 24)) | (realign << 7)]
        self.write(sp, struct.pack("<8I", *frame))
        base = self.rd32(SCB_VTOR) if self.has_vtor else 0
        self.set_regs(ENTRY_WRITE, (sp, EXC_RETURN_HANDLER if nested else EXC_RETURN_THREAD_MSP, exc,
                                    self.rd32(base + 4 * exc)))

    def _interrupt(self, uc, intno, data):
        if intno != EXCP_EXCEPTION_EXIT:
            uc.emu_stop()
            self._fault(f"CPU exception {intno}")
            return
        sp = self.reg(arm.UC_ARM_REG_SP)
        view, at = self.view(sp)
        frame = struct.unpack_from("<8I", view, at)
        xpsr = frame[7]
        # the interrupted handler's IPSR, or 0
        self.set_regs(EXIT_WRITE, frame[:6] + (sp + 32 + (4 if xpsr & (1 << 9) else 0), xpsr & ~(1 << 9),
                                               xpsr & 0x1FF, frame[6] | 1))
        if self.active:
            done, _ = self.active.pop()
            line = self.lines.get(done)
            if line is not None and line():
                self.pending.add(done)
        self._take_exception()  # one waiting follows at once (tail-chaining, B1.5.12)

    def reset(self, vector_table: int) -> None:
        """The core's reset: registers, the system control space; memory
        (RAM and flash) keeps what it holds."""
        uc = self.uc
        self.pending.clear()
        self.enabled.clear()
        self.active = []
        self.fixes, self.late_fixes = [], []
        self._stopping = self._passthrough = None
        self.stall_s = 0.0
        self.reset_cause = None
        self.locked_up = False
        self.asleep = False
        self.write(SCS_BASE, bytes(0x1000))
        self.set_reg(arm.UC_ARM_REG_PRIMASK, 0)
        self.set_reg(arm.UC_ARM_REG_IPSR, 0)
        self.set_reg(arm.UC_ARM_REG_CONTROL, 0)
        self.set_reg(arm.UC_ARM_REG_MSP, self.rd32(vector_table))
        self.set_reg(arm.UC_ARM_REG_SP, self.rd32(vector_table))
        self.set_reg(arm.UC_ARM_REG_LR, 0xFFFFFFFF)
        self.set_reg(arm.UC_ARM_REG_PC, self.rd32(vector_table + 4) | 1)
