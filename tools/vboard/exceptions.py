"""The virtual core's exceptions, entered and left as ARM says.

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
priority the lower exception number goes first (B1.5.4). HardFault's is -1;
the M3's MemManage, BusFault and UsageFault take SHPR1's (faults.py, which
also decides which exception a fault is)."""
import struct

from unicorn import arm_const as arm

from .faults import HARD_FAULT, MEM_MANAGE, USAGE_FAULT
from .system_space import FIRST_IRQ, ICSR_PENDSTSET, NVIC_IPR, SCB_ICSR, SCB_SHPR3, SCB_VTOR, SCS_BASE, SYSTICK

NMI = 2

EXC_RETURN_THREAD_MSP = 0xFFFFFFF9
EXCP_EXCEPTION_EXIT = 8  # QEMU's, as Unicorn reports it
# QEMU's exception numbers (target/arm/cpu.h) as Unicorn reports them -> the fault
QEMU_FAULT_KINDS = {1: "undef", 3: "bus_fetch", 4: "bus_data", 17: "undef", 18: "invstate"}
FRAME_REGS = (arm.UC_ARM_REG_R0, arm.UC_ARM_REG_R1, arm.UC_ARM_REG_R2, arm.UC_ARM_REG_R3,
              arm.UC_ARM_REG_R12, arm.UC_ARM_REG_LR)
ENTRY_READ = FRAME_REGS + (arm.UC_ARM_REG_SP, arm.UC_ARM_REG_XPSR, arm.UC_ARM_REG_PC)
ENTRY_WRITE = (arm.UC_ARM_REG_SP, arm.UC_ARM_REG_LR, arm.UC_ARM_REG_IPSR, arm.UC_ARM_REG_PC)
EXIT_WRITE = FRAME_REGS + (arm.UC_ARM_REG_SP, arm.UC_ARM_REG_XPSR, arm.UC_ARM_REG_IPSR, arm.UC_ARM_REG_PC)

EXC_RETURN_HANDLER = 0xFFFFFFF1


class Exceptions:
    """Exception entry and return of Core (core.py), which mixes this in:
    it has pending, enabled, active, lines, taken and its registers and
    memory (reg, regs, set_regs, rd32, wr32, write, view)."""

    def wake_pending(self) -> bool:
        """An exception that ends a WFI: pending and enabled (B1.5.19)."""
        return any(e < FIRST_IRQ or (e - FIRST_IRQ) in self.enabled for e in self.pending)


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

    def priority(self, exc: int) -> int:
        if exc == NMI:
            return -2  # B1.5.4: NMI's is fixed at -2
        if exc == HARD_FAULT:
            return -1
        if exc == SYSTICK:
            return self.rd32(SCB_SHPR3) >> 24
        if self.v7m and MEM_MANAGE <= exc <= USAGE_FAULT:
            return self.fault_priority(exc)
        if exc >= FIRST_IRQ:
            irq = exc - FIRST_IRQ
            return self.rd32(NVIC_IPR + (irq & ~3)) >> (8 * (irq & 3)) & 0xFF
        return 0

    def _take_exception(self) -> None:
        """The highest pending exception, if above the execution priority
        (PRIMASK raises it to 0: only HardFault, at -1, gets past)."""
        if not self.pending:
            return
        running = self.active[-1][1] if self.active else 256
        if self.reg(arm.UC_ARM_REG_PRIMASK) & 1:
            running = min(running, 0)
        ready = sorted((self.priority(e), e) for e in self.pending
                       if e < FIRST_IRQ or (e - FIRST_IRQ) in self.enabled)
        if not ready or ready[0][0] >= running:
            return
        prio, exc = ready[0]
        self._enter(exc, prio)

    def _enter(self, exc: int, prio: int) -> None:
        """Exception entry (B1.5.6): the frame pushed, the handler entered.
        Raises KeyError when SP is not in mapped memory (a lock-up)."""
        self.pending.discard(exc)
        self.taken[exc] = self.taken.get(exc, 0) + 1
        nested = bool(self.active)
        if exc == SYSTICK:
            self.wr32(SCB_ICSR, self.rd32(SCB_ICSR) & ~ICSR_PENDSTSET)
        *stacked, sp, xpsr, pc = self.regs(ENTRY_READ)
        realign = sp & 4
        sp = (sp - 32) & ~7
        frame = struct.pack("<8I", *(stacked + [pc & ~1, (xpsr | (1 << 24)) | (realign << 7)]))
        self.view(sp + 28)  # KeyError before anything changes: nowhere to stack
        if self.mpu_on and not self.mpu_allows(sp, 32, write=True):
            exc, prio = self._stacking_fault(exc, prio, sp, frame)
            if exc is None:
                self.locked_up = True
                return
        else:
            self.write(sp, frame)
        self.active.append((exc, prio))
        self._mark_active(exc, True)
        base = self.rd32(SCB_VTOR) if self.has_vtor else 0
        self.set_regs(ENTRY_WRITE, (sp, EXC_RETURN_HANDLER if nested else EXC_RETURN_THREAD_MSP, exc,
                                    self.rd32(base + 4 * exc)))

    def _stacking_fault(self, exc: int, prio: int, sp: int, frame: bytes):
        """The MPU refused some of the frame (MSTKERR): the words it
        allows are written, and the higher of the fault and the exception
        is entered on that frame, the other left pending (B1.5.15)."""
        for at in range(0, 32, 4):
            if self.mpu_allows(sp + at, 4, write=True):
                self.write(sp + at, frame[at:at + 4])
        fault = self.fault_exception("mem_stack")
        if fault is None or exc == HARD_FAULT:
            return None, None
        fault_prio = self.priority(fault)
        if fault_prio < prio:
            self.taken[exc] -= 1
            self.pending.add(exc)
            self.taken[fault] = self.taken.get(fault, 0) + 1
            return fault, fault_prio
        self.pending.add(fault)
        return exc, prio

    def _interrupt(self, uc, intno, data):
        if intno != EXCP_EXCEPTION_EXIT:
            uc.emu_stop()
            self.fault_pending = (f"CPU exception {intno}", QEMU_FAULT_KINDS.get(intno, "undef"))
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
            self._mark_active(done, False)
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
        self.fault_pending = None
        self.write(SCS_BASE, bytes(0x1000))
        self._reset_mpu()
        self.spin_at = 0
        self.set_reg(arm.UC_ARM_REG_PRIMASK, 0)
        self.set_reg(arm.UC_ARM_REG_IPSR, 0)
        self.set_reg(arm.UC_ARM_REG_CONTROL, 0)
        self.set_reg(arm.UC_ARM_REG_MSP, self.rd32(vector_table))
        self.set_reg(arm.UC_ARM_REG_SP, self.rd32(vector_table))
        self.set_reg(arm.UC_ARM_REG_LR, 0xFFFFFFFF)
        self.set_reg(arm.UC_ARM_REG_PC, self.rd32(vector_table + 4) | 1)
