"""An angle move as the packets carry it: its profile (interval or velocity,
ramps) and options, in the packet's units, checked once, and how long the
firmware will plan it to take."""
from dataclasses import dataclass
from typing import Optional

from .checks import MIN_RAMP_MS, check_profile
from .profile import positions, smooth_window, smoothed, smoothed_phases, velocity_timing


@dataclass(frozen=True)
class MoveRequest:
    acc_ms: int = MIN_RAMP_MS
    dec_ms: int = MIN_RAMP_MS
    interval_ms: Optional[int] = None  # by interval (packets 8, 11, 13, 14) ...
    velocity: Optional[int] = None     # ... or by velocity, 0.1 deg/s (12, 15)
    power_mw: int = 0
    multi_turn: bool = False
    ramps: bool = True  # False: the plain angle packets 8 and 13, which ramp 20 ms

    def __post_init__(self):
        check_profile(self.acc_ms, self.dec_ms, self.interval_ms, self.velocity)

    def phases_ms(self, distance_decideg: int) -> tuple:
        """The planned profile's acceleration, cruise and deceleration, in ms,
        for a move of this distance (motion/profile.c's timing)."""
        acc, dec = max(self.acc_ms, MIN_RAMP_MS), max(self.dec_ms, MIN_RAMP_MS)
        if not self.ramps:
            acc = dec = MIN_RAMP_MS
        if self.velocity is not None:
            return velocity_timing(distance_decideg, 0.0, self.velocity / 1000.0, acc, dec)
        interval = max(self.interval_ms, acc + dec)
        return acc, interval - acc - dec, dec

    def planned_ms(self, distance_decideg: int, jerk_limit: int = 0) -> tuple:
        """(acceleration, cruise, deceleration, window) in ms: the phases,
        and the window a jerk limit (item 70) averages them over, which
        the move takes longer (motion/planning.c)."""
        phases = smoothed_phases(*self.phases_ms(distance_decideg), jerk_limit)
        return phases + (smooth_window(distance_decideg, *phases, jerk_limit),)

    def planned_s(self, distance_decideg: int, jerk_limit: int = 0) -> float:
        return sum(self.planned_ms(distance_decideg, jerk_limit)) / 1000.0

    def plan(self, start: int, target: int, jerk_limit: int = 0) -> list:
        """The planned position (0.1 deg) at every ms, as the servo runs it."""
        *phases, window = self.planned_ms(target - start, jerk_limit)
        return smoothed(positions(start, target, *phases), window)
