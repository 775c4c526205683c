"""Checks of the values a command sends, in the user's units: whole numbers
within the packet's range, and profiles the firmware would not clamp. Every
message says the range and the unit."""
import math

from . import protocol as p
from .errors import ValueOutOfRange


def check_range(name: str, value: int, low: int, high: int, unit: str = "", per_unit: int = 1) -> int:
    """value, a whole number of 1/per_unit unit, within low..high; the
    message speaks unit (an angle in 0.1 deg is checked with "deg", 10)."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueOutOfRange(f"{name} takes a whole number{' of ' + unit if unit else ''}, not {value!r}"
                              f"{' (move_to() takes degrees)' if name == 'angle' else ''}")
    if not low <= value <= high:
        def show(v):
            return f"{v / per_unit:g}" if per_unit != 1 else str(v)
        raise ValueOutOfRange(f"{name} must be {show(low)}..{show(high)}{' ' + unit if unit else ''}, "
                              f"not {show(value)}")
    return value


# The shortest ramp the firmware keeps (the schema's acc_interval range):
# acc and dec at least this, interval >= acc + dec (docs/protocol.md).
MIN_RAMP_MS = p.field_range(p.ANGLE_BY_INTERVAL, "acc_interval")[0]


def check_profile(acc_ms: int, dec_ms: int, interval_ms: int = None, velocity: int = None) -> None:
    """Refuses a profile the firmware would clamp (docs/protocol.md, "Moves"):
    the move would run, but not as asked."""
    for name, ramp in (("acceleration time", acc_ms), ("deceleration time", dec_ms)):
        if ramp < MIN_RAMP_MS:
            raise ValueOutOfRange(f"{name} must be {MIN_RAMP_MS} ms or more, not {ramp} ms "
                                  f"(the servo would stretch it to {MIN_RAMP_MS} ms)")
    if interval_ms is not None and interval_ms < acc_ms + dec_ms:
        raise ValueOutOfRange(f"a move of {interval_ms} ms cannot hold its ramps ({acc_ms} + {dec_ms} ms): "
                              f"give {acc_ms + dec_ms} ms or more (the servo would stretch it)")
    if velocity is not None:
        check_range("speed", velocity, *p.field_range(p.ANGLE_BY_VELOCITY, "target_velocity"), "deg/s", 10)


def scaled(value: float, factor: int, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueOutOfRange(f"{name} takes a finite number, not {value!r}")
    if not math.isfinite(value * factor):  # 1e308 degrees: finite, not in any unit's range
        raise ValueOutOfRange(f"{name} {value!r} is beyond any range it takes")
    return int(round(value * factor))


def to_ms(seconds: float, name: str) -> int:
    return scaled(seconds, 1000, name)


# The reference servo's motor turns its output at 312 deg/s unloaded from
# 7.4 V (motion/include/motion/gains.h: its datasheet's constants), and in
# proportion to the supply.
NO_LOAD_DPS_PER_V = 312.0 / 7.4


def speed_warning(speed_dps: float, supply_mv: int):
    """A line for the user when speed_dps is beyond what the reference
    motor reaches unloaded at this supply (the move then arrives late, as
    the servo's profile clock waits for the horn), else None."""
    reach = NO_LOAD_DPS_PER_V * supply_mv / 1000.0
    if abs(speed_dps) <= reach:
        return None
    return (f"warning: {abs(speed_dps):g} deg/s is more than the motor turns unloaded at "
            f"{supply_mv / 1000.0:.1f} V (about {reach:.0f} deg/s): the move will arrive late")
