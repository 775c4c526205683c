"""The Cortex-M3's configurable faults and their status registers
(ARMv7-M ARM B1.5.14 "Fault behavior", B3.2.15-B3.2.19), and the M0's
HardFault (ARMv6-M ARM B1.5.14: HardFault is its only fault).

On ARMv7-M a fault is first its own exception: MemManage (4) for an MPU
violation, BusFault (5) for an error response from the bus, UsageFault (6)
for an undefined instruction or an invalid state. Each records why in the
Configurable Fault Status Register (CFSR, 0xE000ED28: MMFSR in bits 0-7,
BFSR 8-15, UFSR 16-31) and, for a data access, the address in MMFAR
(0xE000ED34) or BFAR (0xE000ED38) with MMARVALID or BFARVALID. It is
taken as itself only when SHCSR (0xE000ED24, B3.2.13) enables it
(MEMFAULTENA bit 16, BUSFAULTENA 17, USGFAULTENA 18) and its priority
(SHPR1, 0xE000ED18, B3.2.10: bytes 0-2 for exceptions 4-6) is higher
than the execution priority (the running handler's, 0 under PRIMASK);
else it escalates to HardFault and HFSR (0xE000ED2C, B3.2.16) says
FORCED (bit 30). The status bits stay set until software writes 1 to
them (write-one-to-clear, B3.2.15, B3.2.16). A fault while HardFault runs
cannot be taken: the core locks up (B1.5.15).

An MPU violation on an exception entry's own stacking is MSTKERR, without
MMFAR (B3.2.15); the frame's words the MPU forbids are not written, SP
moves anyway, and the higher of the two (the fault and the exception
being entered) is entered on that frame, the other left pending
(B1.5.15 "Derived exceptions on exception entry")."""
from unicorn import arm_const as arm

HARD_FAULT, MEM_MANAGE, BUS_FAULT, USAGE_FAULT = 3, 4, 5, 6
SCB_SHPR1, SCB_SHCSR, SCB_CFSR, SCB_HFSR = 0xE000ED18, 0xE000ED24, 0xE000ED28, 0xE000ED2C
SCB_MMFAR, SCB_BFAR = 0xE000ED34, 0xE000ED38
SHCSR_ENABLE = {MEM_MANAGE: 1 << 16, BUS_FAULT: 1 << 17, USAGE_FAULT: 1 << 18}  # B3.2.13
SHCSR_ACTIVE = {MEM_MANAGE: 1 << 0, BUS_FAULT: 1 << 1, USAGE_FAULT: 1 << 3}
# CFSR (B3.2.15): MMFSR, BFSR, UFSR
IACCVIOL, DACCVIOL, MSTKERR, MMARVALID = 1 << 0, 1 << 1, 1 << 4, 1 << 7
IBUSERR, PRECISERR, STKERR, BFARVALID = 1 << 8, 1 << 9, 1 << 12, 1 << 15
UNDEFINSTR, INVSTATE = 1 << 16, 1 << 17
HFSR_FORCED = 1 << 30  # B3.2.16
HFSR_W1C = (1 << 31) | HFSR_FORCED | (1 << 1)  # DEBUGEVT, FORCED, VECTTBL
CFSR_W1C = 0x030F9F9B  # the Cortex-M3's status bits of B3.2.15's three registers (no FP: no LSPERR)

# kind -> (its own exception, the CFSR bits it sets, the address register it fills)
KINDS = {
    "mem_data": (MEM_MANAGE, DACCVIOL | MMARVALID, SCB_MMFAR),
    "mem_stack": (MEM_MANAGE, MSTKERR, None),
    "mem_fetch": (MEM_MANAGE, IACCVIOL, None),
    "bus_data": (BUS_FAULT, PRECISERR | BFARVALID, SCB_BFAR),
    "bus_fetch": (BUS_FAULT, IBUSERR, None),
    "bus_stack": (BUS_FAULT, STKERR, None),
    "undef": (USAGE_FAULT, UNDEFINSTR, None),
    "invstate": (USAGE_FAULT, INVSTATE, None),
}


ENTRY_CYCLES = {True: 12, False: 16}  # an exception's entry, by whether the core is ARMv7-M


class Faults:
    """Mixed into Core: v7m (an ARMv7-M core), its registers and memory,
    active, pending, on_write and fix."""

    def _init_faults(self) -> None:
        self.fault_at_s = None        # core time of the last faulting instruction
        self.fault_kind = None
        self.fault_pc = None          # ... and its address (the PC the frame holds)
        self.on_fault = None          # called after a fault is taken (inject.py watches the bridge)
        if self.v7m:
            self.on_write(SCB_CFSR, self._w1c(SCB_CFSR, CFSR_W1C))
            self.on_write(SCB_HFSR, self._w1c(SCB_HFSR, HFSR_W1C))

    def _w1c(self, address: int, mask: int):
        def handler(value, old, size):
            self.fix(address, old & ~(value & mask))
        return handler

    def execution_priority(self) -> int:
        """The running handler's priority, 0 under PRIMASK (B1.5.4), 256
        in thread mode with neither."""
        running = min((p for _, p in self.active), default=256)
        if self.reg(arm.UC_ARM_REG_PRIMASK) & 1:
            running = min(running, 0)
        return running

    def fault_exception(self, kind: str, address=None):
        """Records a fault of this kind (KINDS) in the status registers and
        returns the exception it is taken as: its own, HardFault (the M0's
        only one, or escalated), or None when the core must lock up (a fault
        while HardFault runs)."""
        if any(e == HARD_FAULT for e, _ in self.active):
            return None
        if not self.v7m:
            return HARD_FAULT
        exc, bits, far = KINDS[kind]
        if far is not None and address is None:
            bits &= ~(MMARVALID | BFARVALID)  # no address to give
        self.wr32(SCB_CFSR, self.rd32(SCB_CFSR) | bits)
        if far is not None and address is not None:
            self.wr32(far, address)
        if self.rd32(SCB_SHCSR) & SHCSR_ENABLE[exc] and self.priority(exc) < self.execution_priority():
            return exc
        self.wr32(SCB_HFSR, self.rd32(SCB_HFSR) | HFSR_FORCED)
        return HARD_FAULT

    def fault_priority(self, exc: int) -> int:
        """SHPR1's byte for MemManage, BusFault, UsageFault (B3.2.10)."""
        return self.rd32(SCB_SHPR1) >> (8 * (exc - MEM_MANAGE)) & 0xFF

    def _fault(self, why: str, kind: str = "bus_data", address=None, at_s=None) -> None:
        """A fault at the instruction the PC holds (not carried out): its
        exception entered now (the firmware's handlers spin until the
        watchdog resets), or a lock-up when it cannot be: a fault while
        HardFault runs, or a stack pointer outside RAM (B1.5.15)."""
        self.fault = why
        self.fault_kind = kind
        if at_s is None:
            at_s = self.time_s + (max(self.count.executed - 1, 0) if self.running else 0) * self.cpi / self.hz
        self.fault_at_s = at_s
        self.fault_pc = self.reg(arm.UC_ARM_REG_PC) & ~1
        exc = self.fault_exception(kind, address)
        if exc is None:
            self.locked_up = True
            return
        try:
            self._enter(exc, self.priority(exc))
            # The entry's own time, which the instruction counts leave out:
            # 12 cycles on the Cortex-M3, 16 on the Cortex-M0, with no wait
            # states (Cortex-M3 TRM r1p1 5.5.1, Cortex-M0 TRM r0p0 5.4; the
            # F103's flash wait states would add to it).
            self.time_s += ENTRY_CYCLES[self.v7m] / self.hz
        except KeyError:
            self.locked_up = True
        if self.on_fault is not None:
            self.on_fault()

    def _mark_active(self, exc: int, active: bool) -> None:
        if self.v7m and exc in SHCSR_ACTIVE:
            shcsr = self.rd32(SCB_SHCSR)
            self.wr32(SCB_SHCSR, shcsr | SHCSR_ACTIVE[exc] if active else shcsr & ~SHCSR_ACTIVE[exc])
