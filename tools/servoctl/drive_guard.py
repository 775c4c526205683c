"""Before a bring-up command drives the horn open loop through its travel
(identify, calibrate, tune): a servo whose angle limits are on and
narrower than the factory's is in a joint, and those limits are the
joint's range, which the command would turn it past (identify went to
111 deg on a servo limited to +-10). It refuses unless told the horn is
free (--past-limits); the factory's limits, on a servo just unpacked, are
no such sign."""
from .errors import NoReply, ServoError, UsageError
from .registers import BY_NAME

ANGLE_MOST = 1800  # the limits' range, 0.1 deg (items 51, 52)


def narrowed_limits(servo):
    """(min, max) in 0.1 deg where the angle limits are on and narrower
    than the factory's, else None."""
    if not servo.read("angle_limit_on"):
        return None
    low, high = servo.read("angle_min"), servo.read("angle_max")
    if low > BY_NAME["angle_min"].default or high < BY_NAME["angle_max"].default:
        return low, high
    return None


def check_horn_free(servo, command: str, past_limits: bool,
                    what: str = "turns the horn past them, open loop (docs/bring-up.md)",
                    fix: str = "Free the horn, then give --past-limits (servoctl ui: tick 'horn free')") -> None:
    """UsageError (nothing moved) where the limits say the horn is in a joint."""
    try:
        limits = None if past_limits else narrowed_limits(servo)
    except NoReply:  # as the command itself would say it (outcome.taken)
        raise NoReply(f"servo {servo.id} did not answer: is it on the bus, at this baud rate?") from None
    if limits is not None:
        low, high = limits
        raise UsageError(
            f"servo {servo.id}: its angle limits are on at {low / 10:.1f}..{high / 10:.1f} deg, narrower than "
            f"the factory's: a joint's range. {command} {what}. {fix} (or turn the limits off: 'servoctl "
            f"config set {servo.id} angle_limit_on 0'); nothing was done")


def move_limits(start_decideg: int, limits: tuple) -> tuple:
    """A joint's angle limits (min, max) where a new zero at start reads
    them (the same horn positions): each is start less; beyond the items'
    range, ServoError (before the zero is written)."""
    low, high = (v - start_decideg for v in limits)
    if low < -ANGLE_MOST or high > ANGLE_MOST:
        raise ServoError(f"the angle limits {limits[0] / 10:.1f}..{limits[1] / 10:.1f} deg would be "
                         f"{low / 10:.1f}..{high / 10:.1f} from a zero here, beyond +-180: move the horn "
                         "nearer the middle of its range, or calibrate with --keep-zero")
    return low, high


def write_limits(limits: tuple, min_now: int, write) -> None:
    """Lowered, min first; raised, max first: min stays below max (the
    servo refuses a write that would cross them). write(name, value)."""
    low, high = limits
    order = [("angle_min", low), ("angle_max", high)]
    for name, value in order if low < min_now else order[::-1]:
        write(name, value)
