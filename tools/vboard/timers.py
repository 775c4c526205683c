"""The bridge's PWM timer and the independent watchdog.

TIM3 (RM0008 15, RM0360 13): channels 1 and 2 in PWM mode 1 drive the two
half-bridges' inputs; the motor sees duty CCR / (ARR + 1), the sign by
which channel is on, and coasts when both inputs stay low: both compares 0,
an output disabled (CCxE = 0: OCx not active, RM0008 15.4.9, RM0360 13.4.9), or
PA6/PA7 not the timer's. A stopped counter (CR1.CEN = 0) does not turn
them off: the counter keeps its value, and OCxREF with it, so each pin
keeps its level (high while CNT < CCRx in PWM mode 1, RM0008 15.3.9,
RM0360 13.3 "PWM mode"): a pin left high drives the motor at full duty, both high
brake it. The counter's value when it stopped comes from the time it ran
at the timer's clock (TIMxCLK = HCLK with the APB prescaler at 1, else
twice the APB clock: RM0008 7.2's clock tree, RM0360 6.2's) over
PSC + 1, modulo ARR + 1.

The IWDG (RM0008 19, RM0360 18): started by its key, counting down at the
LSI's frequency (the part's typical, hal/ports/parts.toml: 40 kHz on
the F103 and F030, DS5319/DS9773) divided by 4 << PR from RLR; a reload
key starts it over; reaching 0 resets the chip. Once started it cannot be
stopped."""
from unicorn import UC_HOOK_MEM_WRITE

from .model import Model


class BridgeTimer(Model):
    def __init__(self, board, periph, pins_ok):
        super().__init__(board, periph)
        self.pins_ok = pins_ok  # the board's check that PA6/PA7 are the timer's
        self.started_s = 0.0    # when CEN was last set
        self.frozen_cnt = 0     # CNT while the counter is stopped
        self.watch("CR1", self._cr1)

    def reset(self) -> None:
        super().reset()
        self.started_s, self.frozen_cnt = 0.0, 0

    def _timer_hz(self) -> float:
        rcc = self.board.rcc
        field = "PPRE1" if "PPRE1" in rcc.p.registers["CFGR"][2] else "PPRE"
        code = (rcc.get("CFGR") & rcc.bit("CFGR", field)) >> rcc.p.shift("CFGR", field)
        hz = self.core.hz
        return hz if code < 4 else 2 * (hz >> (code - 3))

    def _cr1(self, value, old, size):
        now = self.core.time_s
        if value & 1 and not old & 1:
            self.started_s = now - self.frozen_cnt * (self.get("PSC") + 1) / self._timer_hz()
        elif old & 1 and not value & 1:
            ticks = (now - self.started_s) * self._timer_hz() / ((self.get("PSC") & 0xFFFF) + 1)
            self.frozen_cnt = int(ticks) % ((self.get("ARR") & 0xFFFF) + 1)

    def duty(self) -> float:
        """-1..1, or None when the bridge is off (coasting)."""
        w, i = self.w, self.i
        return self.duty_of(w[i["CR1"]], w[i["CCER"]], w[i["CCR1"]], w[i["CCR2"]], w[i["ARR"]])

    def duty_of(self, CR1, CCER, CCR1, CCR2, ARR) -> float:  # noqa: N803 (the registers' names)
        """The duty these register values give (None: both inputs low)."""
        if not self.pins_ok():
            return None
        top = (ARR & 0xFFFF) + 1
        on1, on2 = CCER & 1, CCER & (1 << 4)
        if CR1 & 1:
            a = min(CCR1 & 0xFFFF, top) if on1 else 0
            b = min(CCR2 & 0xFFFF, top) if on2 else 0
        else:  # stopped: each pin frozen at its level
            a = top if on1 and self.frozen_cnt < (CCR1 & 0xFFFF) else 0
            b = top if on2 and self.frozen_cnt < (CCR2 & 0xFFFF) else 0
        if a == 0 and b == 0:
            return None
        return (a - b) / top


class Watchdog(Model):
    """Until it starts, every key written is seen (a hook on KR); once
    running, only reloads follow, one each main-loop pass: the hook goes and
    each slice boundary takes a 0xAAAA found in KR as a reload in that
    slice (and clears it), which is as exact as the slice (1 ms at most,
    against a timeout of 72 ms)."""

    def __init__(self, board, periph):
        super().__init__(board, periph)
        self.kr = self.addr("KR")
        self.i_kr = self.i["KR"]
        self.hook = None
        self.running = False
        self.kicked_s = 0.0
        self.bites_s = float("inf")  # when it resets the chip unless reloaded first

    def reset(self) -> None:
        super().reset()
        self.running, self.kicked_s, self.bites_s = False, 0.0, float("inf")
        if self.hook is None:
            self.hook = self.core.uc.hook_add(UC_HOOK_MEM_WRITE, self._hook, begin=self.kr, end=self.kr + 3)

    def _hook(self, uc, access, address, size, value, data):
        self._kr(value, 0, size)

    def _period_s(self) -> float:
        prescaler = 4 << (self.get("PR") & 7)
        return ((self.get("RLR") & 0xFFF) + 1) * prescaler / self.board.part_facts["lsi_hz"]

    def _kr(self, value, old, size):
        """The main loop's reload comes every pass: the fast path first.
        (KR reads as written here; it reads 0 on silicon, and the firmware
        never reads it.)"""
        key = value & 0xFFFF
        if key == 0xAAAA:
            self._kick(self.core.time_s)
        elif key == 0xCCCC:
            self.running = True
            self._kick(self.core.time_s)

    def _kick(self, now_s: float) -> None:
        """A reload: the counter starts over from RLR, at PR's rate, as
        they are at the reload (RM0008 19.3, RM0360 18.3)."""
        self.kicked_s = now_s
        self.bites_s = now_s + self._period_s()

    def step(self, now_s: float) -> None:
        if not self.running or not self.core.ran:  # a key comes only from code that ran
            return
        if self.hook is not None:
            self.core.uc.hook_del(self.hook)
            self.hook = None
        if self.w[self.i_kr] & 0xFFFF == 0xAAAA:
            self._kick(now_s)
            self.w[self.i_kr] = 0

    def next_event_s(self, now_s: float) -> float:
        return self.bites_s

    def expired(self, now_s: float) -> bool:
        return now_s >= self.bites_s
