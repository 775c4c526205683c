"""A robot loop's cycle on the wire: its bytes, the most cycles a second
the wire carries at a baud rate, and the refusal of a period it cannot
carry (stream.RobotLoop and servoctl stream)."""
import warnings
from dataclasses import dataclass

from . import protocol as p
from .errors import ValueOutOfRange

BITS_PER_BYTE = 10  # 8N1


def wire_bytes(code: int, content: bytes) -> int:
    return len(p.request_frame(code, content))


@dataclass
class LoopRate:
    cycles: int
    seconds: float           # on the bus's clock
    wire_limit_hz: float     # the cycle's bytes back to back at the baud rate

    @property
    def rate_hz(self) -> float:
        return self.cycles / self.seconds if self.seconds > 0 else 0.0

    @property
    def ratio(self) -> float:
        return self.rate_hz / self.wire_limit_hz


class LoopLate(RuntimeWarning):
    """A RobotLoop cycle began a period or more after it was due: the host
    (or the answers it waited for) fell behind its period."""


def cycle_bytes(ids: list) -> int:
    """A robot loop's cycle on the wire: the setpoints (one StreamSetpoint,
    or a SyncCommand of them), the Sync Monitor and every answer."""
    setpoints = p.SYNC, bytes([p.STREAM_SETPOINT, 9, len(ids)]) + bytes(9 * len(ids))
    monitor = p.SYNC, bytes([p.MONITOR, 1, len(ids)] + list(ids))
    if len(ids) == 1:
        setpoints = p.STREAM_SETPOINT, bytes(9)
    return wire_bytes(*setpoints) + wire_bytes(*monitor) + len(ids) * p.answer_frame_size(p.MONITOR)


def wire_limit_hz(ids: list, baud: int) -> float:
    """The most cycles a second the wire carries: every byte back to back."""
    return baud / BITS_PER_BYTE / cycle_bytes(ids)


def check_wire(ids: list, period_s: float, baud: int, where: str = "") -> None:
    """Refuses, before anything is sent, a period shorter than the cycle's
    own bytes on the wire (ValueOutOfRange): such a loop cannot keep it."""
    limit = wire_limit_hz(ids, baud)
    if 1.0 / period_s > limit:
        raise ValueOutOfRange(
            f"{where}{1.0 / period_s:g} Hz is beyond the wire: a cycle for {len(ids)} servo(s) (setpoints, "
            f"Sync Monitor, answers) is {cycle_bytes(ids)} bytes, {1000.0 / limit:.2f} ms at {baud} baud, "
            f"so the wire allows at most {limit:.1f} Hz. Use a longer period, a higher baud rate or fewer servos")


def warn_late(cycle: int, late_s: float, period_s: float, rate: LoopRate, baud: int) -> None:
    """LoopLate for a cycle that began late_s after it was due."""
    warnings.warn(LoopLate(
        f"RobotLoop: cycle {cycle} began {late_s * 1000:.1f} ms late: the loop cannot keep its "
        f"{period_s * 1000:g} ms period ({rate.rate_hz:.1f} Hz run of {1 / period_s:g} Hz; the wire allows "
        f"{rate.wire_limit_hz:.1f} Hz at {baud} baud)"), stacklevel=4)
