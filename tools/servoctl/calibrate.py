"""servoctl calibrate: how this servo's parts are put together, found with
the horn free and stored (data items 82's sign, 90 and 91).

1. The current amplifier's zero (item 91): with the output released no
   current flows, so the smallest zero at which the servo reads 0 mA is the
   amplifier's output then, in ADC counts (a binary search, each step a
   write and a wait for the current's 8 ms filter).
2. The direction (item 82's sign): a short open-loop push at a positive
   duty (DriveDuty, before anything runs closed loop: a loop the wrong way
   round runs away). Where the angle falls, the gear ratio is negated and
   the bridge is driven the other way from then on; a second push checks it.
3. The zero (item 90): the horn is taken back to where it started, closed
   loop, released, and the encoder's count there (item 71) becomes the
   zero: after every power-up angles are from it. SetOriginPoint makes it so
   now. So start with the horn at its zero mark, or pass --keep-zero.
   Angle limits narrower than the factory's (a joint's range, kept on the
   joint) are moved with the zero: they name the same horn positions after.

Every item is written through a PutBack (putback.py): a calibrate that
does not finish (Ctrl-C, the ui's STOP ALL or its tab closing, an error, a
servo gone) puts each item it wrote back as it was, the search's midpoints
in item 91 first of all (left there, the servo reads 0 A while it draws
current, and its current protections are blind).

Time is the servo's (or the simulator's) clock: sleep(s)."""
from dataclasses import dataclass

from .drive_guard import move_limits, narrowed_limits, write_limits
from .errors import ServoError
from .identify import come_to_rest, return_to
from .putback import PutBack


PUSH_DUTY = 0.25
PUSH_MS = 150
CURRENT_SETTLE_S = 0.06   # the current's filter: 8 ms time constant
ADC_MOST = 4095
STORE_SETTLE_S = 0.3


@dataclass
class Calibration:
    current_zero: int       # ADC counts (item 91)
    reversed: bool          # the gear ratio (item 82) is negative
    gear_ratio: int
    encoder_zero: int       # counts (item 90), or None where kept
    push_decideg: int       # what the checking push moved, positive
    limits: tuple = None    # the narrowed angle limits moved with the zero: (min, max) before, after; None: not moved


def current_zero(servo, sleep, kept: PutBack) -> int:
    """The smallest item 91 at which the released servo reads no current;
    each step written through kept."""
    servo.stop("release")
    lo, hi = 0, ADC_MOST  # the answer is in lo..hi
    while lo < hi:
        mid = (lo + hi) // 2
        kept.write("current_zero", mid)
        sleep(CURRENT_SETTLE_S)
        if servo.read("current") == 0:
            hi = mid
        else:
            lo = mid + 1
    kept.write("current_zero", lo)
    return lo


def settle_store(sleep) -> None:
    """A quiet moment with the output released: the store erases its spare
    page then if its page has filled (20-40 ms, docs/decisions-hardware.md),
    and not while a later request waits (a request that arrives during an
    erase is carried out unanswered)."""
    sleep(STORE_SETTLE_S)


def push(servo, sleep, duty: float = PUSH_DUTY) -> int:
    """Decidegrees an open-loop push at duty moved the horn (from rest)."""
    before = servo.read_motion().angle_decideg
    servo.drive_duty(duty, PUSH_MS)
    sleep(PUSH_MS / 1000.0 + 0.02)
    moved = servo.read_motion().angle_decideg - before
    come_to_rest(servo, sleep)
    return moved


def direction(servo, sleep, kept: PutBack) -> tuple:
    """(reversed, the gear ratio now, the checking push in decidegrees)."""
    ratio = servo.read("gear_ratio")
    moved = push(servo, sleep)
    if abs(moved) < 5:
        raise ServoError(f"a push at duty {PUSH_DUTY} moved the horn {moved / 10:.1f} deg: it must turn freely "
                         "(and the supply be on)")
    if moved < 0:
        ratio = -ratio
        kept.write("gear_ratio", ratio)
        settle_store(sleep)
        moved = push(servo, sleep)
        if moved <= 0:
            raise ServoError(f"the horn still turns backwards ({moved / 10:.1f} deg) with the bridge reversed")
    return ratio < 0, ratio, moved


def zero(servo, sleep, start_decideg: int, kept: PutBack) -> int:
    """The horn back at start_decideg, released, and its encoder count
    there stored as the zero (item 90), and taken as the origin now."""
    return_to(servo, sleep, start_decideg)
    servo.stop("release")
    sleep(0.05)
    count = servo.read("encoder_count")
    kept.write("encoder_zero", count)
    servo.set_origin()
    return count


def calibrate(servo, sleep, keep_zero: bool = False) -> Calibration:
    if servo.read("voltage") < 500:
        raise ServoError("the supply reads below 0.5 V: calibrate needs the motor powered")
    start = servo.read_motion().angle_decideg
    joint = None if keep_zero else narrowed_limits(servo)
    moved_to = None if joint is None else move_limits(start, joint)
    with PutBack(servo, "calibrate") as kept:  # all of it, or none: each item as it was
        amp = current_zero(servo, sleep, kept)
        settle_store(sleep)
        reversed_, ratio, moved = direction(servo, sleep, kept)
        count = None if keep_zero else zero(servo, sleep, start, kept)
        if moved_to is not None:
            write_limits(moved_to, kept.servo.read("angle_min"), kept.write)
    return Calibration(amp, reversed_, ratio, count, moved, None if joint is None else (joint, moved_to))
