"""What became of a motion command: did the servo take it, and did the horn
arrive where it was asked to go, or why not. `s` is a servo.Servo (this
module is below it: Servo.move_to waits with it)."""
from dataclasses import dataclass

from . import registers
from .frame import Where, jerk_limit, turn_base
from .errors import BadAnswer, LinkError, NoReply, Refused, ServoError
from .move_request import MoveRequest

TOLERANCE_DEG = 0.5
_BIT = registers.STATUS_MASK
# Status bits under which the servo refuses motion (docs/protocol.md,
# "Protection"): high and low voltage, over-temperature.
INHIBITING = _BIT["high_voltage"] | _BIT["low_voltage"] | _BIT["over_temperature"]
STALL = _BIT["stall"]
COMMAND_ERROR = _BIT["command_error"]
EXECUTING = _BIT["executing"]
# Item 75 at 1 (docs/safety.md, "The servo's own faults"): what it means.
SAFE_MODE = ("safe mode: the output is held off after 3 fault resets in a row ({where}); "
             "a power cycle or an update ends it")


def in_safe_mode(s) -> bool:
    """Item 75 reads 1; False on a servo without it (the maker's)."""
    try:
        return s.read("safe_mode") == 1
    except LinkError:
        raise
    except ServoError:  # the maker's: no item 75
        return False


def taken(s, what: str) -> int:
    """After a command that has no answer of its own: the servo is there
    and did not refuse it. Returns the status byte."""
    try:
        status = s.status()
    except BadAnswer:
        raise
    except NoReply:
        raise NoReply(f"servo {s.id} did not answer: is it on the bus, at this baud rate?") from None
    if status & INHIBITING:
        raise Refused(f"servo {s.id} refused {what}: a protection holds it "
                      f"({', '.join(registers.status_names(status & INHIBITING))})")
    if status & COMMAND_ERROR:
        if in_safe_mode(s):  # read only on a refusal
            raise Refused(f"servo {s.id} refused {what}: it is in " + SAFE_MODE.format(
                where=f"'servoctl faults {s.id}' says which"))
        raise Refused(f"servo {s.id} refused {what} (status: {', '.join(registers.status_names(status))})")
    return status


@dataclass
class Plan:
    start: int        # 0.1 deg, multi-turn
    asked: int        # 0.1 deg, as the user asked
    target: int       # 0.1 deg, after the angle limits
    target_abs: int   # 0.1 deg, multi-turn: where the horn should end
    clamped: bool
    planned_s: float  # the profile's length (a jerk limit's window included)
    soft_start_s: float


def plan_move(s, asked: int, request: MoveRequest, where: Where = None) -> Plan:
    """Where the move will end and how long it is planned to take, from the
    servo's own settings (as frame.check_target read them, or read now):
    angle limits (48, 51, 52) clamp the target (a multi-turn one where item
    48 is 2, in the frame the angles are read in); soft start (49, 50) may
    stretch it; a jerk limit (70) lengthens it by its window."""
    if where is None:
        where = Where(s.read_all(), s.multi_turn_angle()[0], jerk_limit(s))
    cfg, start = where.cfg, where.at
    target = asked
    # Item 48: 1 (the maker's on) clamps a single-turn target, 2 a multi-turn one too.
    if cfg["angle_limit_on"] >= (2 if request.multi_turn else 1):
        target = min(max(asked, cfg["angle_min"]), cfg["angle_max"])
    # A single-turn target is taken within the turn the servo is in.
    target_abs = target if request.multi_turn else turn_base(start) + target
    planned = request.planned_s(target_abs - start, where.jerk)
    soft = cfg["soft_start_time"] / 1000.0 if cfg["soft_start_on"] else 0.0
    return Plan(start, asked, target, target_abs, target != asked, planned, soft)


# What a move stretched to soft_start_time may take beyond it: arriving
# (status bit 0 falls once the horn is nearly still) and the 10 ms polls.
SOFT_START_SETTLE_S = 0.3


def planned_text(plan: Plan, took_s: float) -> str:
    """'planned N ms', and soft start named when it can explain a move that
    took longer: it stretches the first angle move after power-up (items
    49/50) to soft_start_time, no further. A move that took longer than
    that (one that did not arrive: the wait includes the soft start) was
    slowed by something else, whether it was the first move or not."""
    text = f"planned {plan.planned_s * 1000:.0f} ms"
    if plan.soft_start_s and plan.planned_s + 0.1 < took_s <= plan.soft_start_s + SOFT_START_SETTLE_S:
        text += (f"; soft start is on ({plan.soft_start_s * 1000:.0f} ms, soft_start_on/soft_start_time)"
                 f" and stretches the first move after power-up")
    return text


@dataclass
class Outcome:
    arrived: bool
    angle: int        # 0.1 deg, where the horn settled
    took_s: float
    reason: str


def wait_for_arrival(s, plan: Plan, tolerance_deg: float = TOLERANCE_DEG,
                     timeout_s: float = None) -> Outcome:
    """Waits for status bit 0 to fall (the firmware clears it once the horn
    has arrived, nearly still) within a timeout that follows the plan, and
    judges the result against the asked angle."""
    limit = timeout_s if timeout_s is not None else 2.0 * plan.planned_s + plan.soft_start_s + 2.0
    clock = s.bus.clock
    start = clock()
    seen = 0
    status = EXECUTING
    s.bus.sleep(0.01)
    while clock() - start < limit:
        status = s.status()
        seen |= status
        if not status & EXECUTING:
            break
        s.bus.sleep(0.01)
    took = clock() - start
    angle, _ = s.multi_turn_angle()
    off = abs(angle - plan.target_abs) / 10.0
    if status & EXECUTING:
        why = f"did not arrive within {limit:.1f} s ({planned_text(plan, took)})"
        if seen & STALL:
            why = f"blocked: it stalled (status bit 2) and {why}"
        return Outcome(False, angle, took, f"{why}; at {angle / 10:.1f} deg")
    if off > tolerance_deg:
        if seen & INHIBITING:
            why = f"stopped by a protection ({', '.join(registers.status_names(seen & INHIBITING))})"
        elif seen & STALL:
            why = "blocked: it stalled (status bit 2)"
        else:
            why = "stopped short"
        return Outcome(False, angle, took,
                       f"{why} at {angle / 10:.1f} deg, {off:.1f} deg from {plan.target_abs / 10:.1f} deg")
    if plan.clamped:
        return Outcome(False, angle, took,
                       f"at {angle / 10:.1f} deg, not {plan.asked / 10:.1f} deg: clamped by the angle "
                       f"limits (51/52, switch 48)")
    return Outcome(True, angle, took, "")
