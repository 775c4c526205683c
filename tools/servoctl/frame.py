"""Where an angle lands: servoctl's one frame of reference.

An angle, in every command and in the Python API, is the horn's angle from
its origin in degrees, as ReadMultiTurn reports it. A move is single-turn
(-180..180) unless the user asks for multi-turn; it never becomes
multi-turn because of its value or because of what else is in the command.

The firmware takes a single-turn target within the turn the horn is in now
(docs/decisions.md), so at 720 deg "10" would mean 730 deg. servoctl sends a
single-turn move only to a servo in turn 0, where the two readings agree,
and refuses otherwise, saying how to get back. The firmware clamps a
single-turn target to the angle limits (48, 51, 52) within its turn and a
streamed one in this frame, and a multi-turn one too where item 48 is 2 (1,
the maker's "on", lets it pass, as the maker's servo does); servoctl refuses
a target outside the limits in both modes before sending, rather than let
the servo stop short of it."""
from dataclasses import dataclass

from .errors import NotSent, ServoError
from .protocol import BadAnswer, NoReply, ValueOutOfRange, ANGLE, field_range

SINGLE_TURN = field_range(ANGLE, "angle")  # 0.1 deg: a single-turn move's target
TURN = 3600


def turn_base(multi_turn: int) -> int:
    """The whole turns of a multi-turn angle (0.1 deg), as the firmware
    counts them for a single-turn target (ReadAngle wraps into -180.0 ..
    179.9)."""
    within = multi_turn % TURN
    if within >= SINGLE_TURN[1]:
        within -= TURN
    return multi_turn - within


def _deg(decideg: int) -> str:
    return f"{decideg / 10:.1f} deg"


@dataclass
class Where:
    """What a move is checked against: the servo's user area and its
    multi-turn angle (0.1 deg) when it was checked, and its jerk limit
    (item 70; 0: the trapezoid, or a servo without the item)."""
    cfg: dict
    at: int
    jerk: int = 0


def jerk_limit(s) -> int:
    """Item 70, which stretches every angle move (profile.smooth_window);
    0 from a servo without it (the maker's firmware)."""
    try:
        return s.read("jerk_limit")
    except NoReply:
        raise
    except ServoError:
        return 0


def check_target(s, angle: int, multi_turn: bool) -> Where:
    """Refuses a target (0.1 deg) that would not end where it says, before
    anything is sent. Reads the servo's angle and user area (two requests)
    and returns them for planning."""
    if not multi_turn and not SINGLE_TURN[0] <= angle <= SINGLE_TURN[1]:
        raise ValueOutOfRange(
            f"servo {s.id}: {_deg(angle)} is beyond a single turn (-180.0..180.0 deg); a move there is a multi-turn "
            f"move: add --multi-turn (move_to(..., multi_turn=True))")
    try:
        where = Where(s.read_all(), s.multi_turn_angle()[0], jerk_limit(s))
    except BadAnswer:
        raise
    except NoReply:
        raise NoReply(f"servo {s.id} did not answer: is it on the bus, at this baud rate? "
                      f"Nothing was sent") from None
    cfg = where.cfg
    if cfg["angle_limit_on"] and not cfg["angle_min"] <= angle <= cfg["angle_max"]:
        raise ValueOutOfRange(
            f"servo {s.id} limits its angle to {_deg(cfg['angle_min'])}..{_deg(cfg['angle_max'])} "
            f"(angle_min, angle_max, angle_limit_on): {_deg(angle)} is outside them. "
            f"Change the limits, or turn them off with 'servoctl config set {s.id} angle_limit_on 0'")
    base = turn_base(where.at)
    if not multi_turn and base != 0:
        raise NotSent(
            f"servo {s.id} is at {_deg(where.at)}, outside the single turn (-180.0..180.0 deg): a "
            f"single-turn angle is taken within the turn it is in, so {_deg(angle)} would end at "
            f"{_deg(base + angle)}. Add --multi-turn (move_to(..., multi_turn=True)) to go to "
            f"{_deg(angle)}")
    return where
