"""The bridge's PWM timer and the independent watchdog.

TIM3 (RM0008 15, RM0360 13): channels 1 and 2 in PWM mode 1 drive the two
half-bridges; the motor sees duty CCR / (ARR + 1), the sign by which channel
is on, and coasts when both are off or the counter is stopped.

The IWDG (RM0008 19, RM0360 18): started by its key, counting down at the
LSI's 40 kHz (DS5319/DS9773 typical) divided by 4 << PR from RLR; a reload
key starts it over; reaching 0 resets the chip. Once started it cannot be
stopped."""
from unicorn import UC_HOOK_MEM_WRITE

from .model import Model

LSI_HZ = 40_000


class BridgeTimer(Model):
    def __init__(self, board, periph, pins_ok):
        super().__init__(board, periph)
        self.pins_ok = pins_ok  # the board's check that PA6/PA7 are the timer's

    def duty(self) -> float:
        """-1..1, or None when the bridge is off (coasting)."""
        w, i = self.w, self.i
        if not w[i["CR1"]] & 1 or not self.pins_ok():
            return None
        top = (w[i["ARR"]] & 0xFFFF) + 1
        ccer = w[i["CCER"]]
        a = (w[i["CCR1"]] & 0xFFFF) if ccer & 1 else 0
        b = (w[i["CCR2"]] & 0xFFFF) if ccer & (1 << 4) else 0
        if a == 0 and b == 0:
            return None
        return (min(a, top) - min(b, top)) / top


class Watchdog(Model):
    """Until it starts, every key written is seen (a hook on KR); once
    running, only reloads follow, one each main-loop pass: the hook goes and
    each slice boundary takes a 0xAAAA found in KR as a reload in that
    slice (and clears it), which is as exact as the slice (1 ms at most,
    against a timeout of 125 ms)."""

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
        return ((self.get("RLR") & 0xFFF) + 1) * prescaler / LSI_HZ

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
