"""What ARM puts beside a Cortex-M core in its system control space, as
the virtual core models it: the NVIC's enable and pending registers, the
SCB's ICSR and AIRCR (a software reset), and SysTick counting the core's
cycles (ARMv7-M ARM B3.2, B3.3, B3.4; the same on ARMv6-M). Core
(core.py) takes these handlers with its memory and its time."""

# System control space (ARMv7-M ARM B3.2, B3.3, B3.4)
SYST_CSR, SYST_RVR, SYST_CVR = 0xE000E010, 0xE000E014, 0xE000E018
NVIC_ISER, NVIC_ICER, NVIC_ISPR, NVIC_ICPR = 0xE000E100, 0xE000E180, 0xE000E200, 0xE000E280
SCB_ICSR, SCB_VTOR, SCB_AIRCR = 0xE000ED04, 0xE000ED08, 0xE000ED0C
NVIC_IPR, SCB_SHPR3 = 0xE000E400, 0xE000ED20
ICSR_PENDSTSET, ICSR_PENDSTCLR = 1 << 26, 1 << 25
AIRCR_VECTKEY, AIRCR_SYSRESETREQ = 0x05FA0000, 1 << 2
CSR_ENABLE, CSR_TICKINT, CSR_COUNTFLAG = 1, 2, 1 << 16
SYSTICK = 15
FIRST_IRQ = 16
SCS_BASE = 0xE000E000


def scs_word(address: int) -> int:
    """A system control space register's index among the block's words."""
    return (address - SCS_BASE) >> 2


CSR_W, RVR_W, ICSR_W = scs_word(SYST_CSR), scs_word(SYST_RVR), scs_word(SCB_ICSR)


class SystemControlSpace:
    """The handlers of the system control space's registers; the class that
    mixes this in has scs (the block's words), fix, stop, cycles,
    systick_base, enabled, pending and lines."""

    # ---- NVIC and SCB -----------------------------------------------------
    def _nvic(self, word: int, enable: bool):
        def handler(value, old, size):
            for bit in range(32):
                if value >> bit & 1:
                    (self.enabled.add if enable else self.enabled.discard)(32 * word + bit)
            mask = sum(1 << (b - 32 * word) for b in self.enabled if 32 * word <= b < 32 * word + 32)
            self.fix(NVIC_ISER + 4 * word, mask)
            self.fix(NVIC_ICER + 4 * word, mask)
        return handler

    def _nvic_pend(self, word: int, pend: bool):
        def handler(value, old, size):
            for bit in range(32):
                if value >> bit & 1:
                    exc = FIRST_IRQ + 32 * word + bit
                    line = self.lines.get(exc)
                    if pend or (line is not None and line()):
                        self.pending.add(exc)  # a level line still high pends again at once
                    else:
                        self.pending.discard(exc)
            self.fix(NVIC_ISPR + 4 * word, 0)
            self.fix(NVIC_ICPR + 4 * word, 0)
        return handler

    def _icsr(self, value, old, size):
        if value & ICSR_PENDSTSET:
            self.pending.add(SYSTICK)
        if value & ICSR_PENDSTCLR:
            self.pending.discard(SYSTICK)
        self.fix(SCB_ICSR, ICSR_PENDSTSET if SYSTICK in self.pending else 0)

    def _aircr(self, value, old, size):
        if (value & 0xFFFF0000) == AIRCR_VECTKEY and value & AIRCR_SYSRESETREQ:
            self.stop(reset="software")
        self.fix(SCB_AIRCR, 0xFA050000)

    # ---- SysTick (ARMv7-M ARM B3.3) ---------------------------------------
    def _syst_csr(self, value, old, size):
        if value & CSR_ENABLE and not old & CSR_ENABLE:
            self.systick_base = self.cycles
        self.fix(SYST_CSR, value & ~CSR_COUNTFLAG)

    def _syst_cvr(self, value, old, size):
        self.systick_base = self.cycles  # any write clears the counter
        self.fix(SYST_CVR, 0)

    def _update_systick(self) -> None:
        scs = self.scs
        if not scs[CSR_W] & CSR_ENABLE:
            return
        period = (scs[RVR_W] & 0xFFFFFF) + 1
        into = int(self.cycles - self.systick_base) % period
        self.wr32(SYST_CVR, period - 1 - into)

    def _systick_after(self, passed: float) -> None:
        """Wraps in the cycles that passed pend SysTick (one pending at most)."""
        scs = self.scs
        csr = scs[CSR_W]
        if not csr & CSR_ENABLE:
            return
        period = (scs[RVR_W] & 0xFFFFFF) + 1
        before = int(self.cycles - passed - self.systick_base) // period
        after = int(self.cycles - self.systick_base) // period
        if after > before:
            scs[CSR_W] = csr | CSR_COUNTFLAG
            if csr & CSR_TICKINT:
                self.pending.add(SYSTICK)
                scs[ICSR_W] |= ICSR_PENDSTSET

    def cycles_to_systick(self) -> float:
        """Cycles until the counter next wraps (inf when it is off)."""
        scs = self.scs
        if not scs[CSR_W] & CSR_ENABLE:
            return float("inf")
        period = (scs[RVR_W] & 0xFFFFFF) + 1
        return period - (self.cycles - self.systick_base) % period
