"""An arm's calibration on this firmware (servoctl.arm, the LeRobot
plugins): each joint's zero stored on its servo (item 90) where the
person holds the arm, and its range as the servo's angle limits."""
from . import registers
from .drive_guard import ANGLE_MOST, narrowed_limits, write_limits
from .errors import UsageError
from .servo import Servo


def set_zero_here(arm) -> dict:
    """Each joint released, its encoder count now stored as its zero
    (item 90) and taken as the origin (SetOriginPoint): it reads 0 deg
    here from now on, after a power-up too. A joint's range (limits
    narrower than the factory's) is moved with the zero, the same horn
    positions (what of it lies beyond +-180 from here cut off), until
    store_ranges() stores the new one: a calibration cut short (Ctrl-C,
    a crash) leaves the old range on, not none. Other limits are off
    until then. {name: the count}."""
    counts = {}
    for name, servo_id in arm.joints.items():
        s = Servo(arm.bus, servo_id)
        s.stop("release")
        joint = narrowed_limits(s)
        moved = None
        if joint is not None:  # beyond +-180 from here: the part that can be said, still on
            here = s.read_motion().angle_decideg
            moved = (max(joint[0] - here, -ANGLE_MOST), min(joint[1] - here, ANGLE_MOST))
            moved = moved if moved[1] - moved[0] >= 10 else None
        if moved is None:
            s.write("angle_limit_on", 0)
        else:
            write_limits(moved, joint[0], s.write)
        counts[name] = s.read("encoder_count")
        s.write("encoder_zero", counts[name])
        s.set_origin()
    return counts


def store_ranges(arm, ranges: dict) -> None:
    """{name: (lowest, highest) deg} stored as each servo's angle limits
    (items 52, 51, switched on by 48), which every move and setpoint
    keeps to, the servo's own."""
    for name, (low, high) in ranges.items():
        s = Servo(arm.bus, arm.joints[name])
        lo, hi = round(low * 10), round(high * 10)
        if hi - lo < 10:
            raise UsageError(f"{name} moved {abs(hi - lo) / 10:.1f} deg: move each joint through its range")
        s.write("angle_limit_on", 0)
        s.write("angle_min", lo)
        s.write("angle_max", hi)
        s.write("angle_limit_on", 1)


def ranges_stored(limits: dict) -> bool:
    """Whether every joint's servo keeps its angle limits on, and not
    the factory's (on, +-135 deg: a new servo's, no calibration's)."""
    factory = (registers.find("angle_min").default, registers.find("angle_max").default)
    return all(lim.angle_min is not None and (lim.angle_min, lim.angle_max) != factory
               for lim in limits.values())
