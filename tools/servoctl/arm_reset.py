"""A servo of an arm (servoctl.arm) that restarts mid-run, its supply
dipped or its connector loose: items 64-72 are RAM, so it comes back
with its bus watchdog off (0 ms, damp) and its output released, and the
stream's next setpoint would drive it from wherever its horn fell to at
the motor's top speed, with no ramp.

Its bus watchdog is how it is told: while the arm is driven each servo
holds the arm's watchdog_ms, and a servo that reads anything else has
restarted (or been set by another program). A restart is silent first:
the bootloader listens for 0.2 s (BOOT_LISTEN_MS) before it starts the
application. So each frame reads item 64 of enough servos, in turn, that
each is read at least every CHECK_EVERY_S, half that silence; a servo
that does not answer (in its bootloader, or its cable out) is read every
frame from then on, until it answers: it is caught in its first frame
back, held a few ms after that frame's setpoint reached it. The reads
follow the setpoints, so the setpoints keep the frames' times. One
ReadData a servo read, with a short time-out; none on the maker's firmware, nor
with watchdog_ms 0 (the arm leaves the watchdog as it is)."""
import math

from . import protocol as p
from . import registers
from .errors import NoReply

CHECK_EVERY_S = 0.1
WATCHDOG_MS = registers.find("watchdog_ms")


class ResetWatch:
    def __init__(self, ids, watchdog_ms: int):
        self.ids, self.watchdog_ms = list(ids), watchdog_ms
        self.silent = []  # not answering at their last read: read every frame
        self._next = 0

    def went_silent(self, ids) -> None:
        """ids did not answer elsewhere (a Sync Monitor): read every frame."""
        self.silent += [i for i in ids if i not in self.silent]

    def due(self, period_s: float) -> list:
        """The servos to read this frame: the silent ones, then the next in
        turn, as many as keep each read every CHECK_EVERY_S at period_s."""
        count = min(len(self.ids), math.ceil(len(self.ids) * max(period_s, 0.0) / CHECK_EVERY_S) or 1)
        turn = [self.ids[(self._next + k) % len(self.ids)] for k in range(count)]
        self._next = (self._next + count) % len(self.ids)
        return self.silent + [i for i in turn if i not in self.silent]

    def restarted(self, bus: p.Bus, period_s: float) -> list:
        """[(id, the watchdog_ms it reads)] of the servos read this frame
        that do not hold the arm's; a silent one stays in the silent list."""
        window = 12 * 10 / bus.serial.baudrate + 0.003  # scan.reply_window_s: a short answer and its turn
        out = []
        for servo_id in self.due(period_s):
            try:
                content = bus.request(p.READ_DATA, bytes([servo_id, WATCHDOG_MS.id]), timeout=window, again=False)
                ms = WATCHDOG_MS.unpack(content[2:])
            except NoReply:
                self.went_silent([servo_id])
                continue
            if servo_id in self.silent:
                self.silent.remove(servo_id)
            if ms != self.watchdog_ms:
                out.append((servo_id, ms))
        return out
