"""Where a joint's horn stands against its angle limits, and the short way
back to them (servoctl.arm, at connect and after a restart).

A servo reads its horn in the multi-turn frame (ReadMultiTurn, the Sync
Monitor): 188 deg is 188 deg there, 0 turns in 'servoctl info', and the
same horn reads -172 deg after its turns are reset or a power-up (the
firmware puts the reading within half a turn of the zero, position.c). The
angle limits, and so every streamed setpoint, hold in that frame. So a
joint is taken where its horn physically stands, modulo a turn:

- inside its limits, or outside them by less than the way round to the
  other limit (188 with limits -36.9..175.2 is 12.8 deg past 175.2, not
  135.1 below -36.9), with the reading in that place's turn: it is held,
  or moved to the nearest limit that short way;
- its reading a whole number of turns away from that place (wheel mode,
  multi-turn moves, or the wrap at +-180 deg): resetting its turns puts it
  back, or, where the reset would land in the wrong turn (-172 for a horn
  12.8 deg past 175.2), the short way leads across the wrap, and the
  reset is made there (Way.goal, reframe).

Decidegrees, as the servo counts; limits are setpoints.Limits."""
from dataclasses import dataclass

from . import protocol as p
from .servo import Servo

TURN = 3600


def _wrap(decideg: int) -> int:
    """Within -180.0 .. 179.9 deg, as ResetMultiTurn leaves the origin's frame."""
    return (decideg + TURN // 2) % TURN - TURN // 2


@dataclass
class Way:
    """reading: what the servo reads (0.1 deg). place: where its horn
    stands, in the turn nearest its limits. limit: the nearest limit by the
    short way where the horn is outside them, else None. turns: the whole
    turns the reading counts beyond place."""
    reading: int
    place: int
    limit: int = None
    turns: int = 0

    @property
    def goal(self):
        """The limit in the reading's turn: where a move takes it, the short way."""
        return None if self.limit is None else self.limit + self.turns * TURN

    @property
    def past(self) -> float:
        return 0.0 if self.limit is None else abs(self.place - self.limit) / 10


def way_back(decideg: int, lim) -> Way:
    """Where a horn reading decideg stands against lim (setpoints.Limits;
    off: a target is taken within -180..180 deg, the place's turn)."""
    if lim.angle_min is None:
        place, limit = _wrap(decideg), None
    else:
        lo, hi = lim.angle_min, lim.angle_max
        u = (decideg - lo) % TURN
        if u <= hi - lo:
            place, limit = lo + u, None
        elif u - (hi - lo) <= TURN - u:  # past the upper limit, not as far round to the lower
            place, limit = hi + u - (hi - lo), hi
        else:
            place, limit = lo - (TURN - u), lo
    return Way(decideg, place, limit, (decideg - place) // TURN)


def after_reset(decideg: int, center_offset: int) -> int:
    """The reading once the turns are reset (ResetMultiTurn: the origin's
    frame within half a turn; the reading is that minus the center offset,
    item 53)."""
    return _wrap(decideg + center_offset) - center_offset


def _deg(decideg: int) -> str:
    return f"{decideg / 10:.1f} deg"


def where(way: Way, lim) -> str:
    """Where the horn stands, as a phrase."""
    if way.limit is None:
        return f"its horn at {_deg(way.place)}" + ("" if lim.angle_min is None else ", within its limits")
    side = "upper" if way.limit == lim.angle_max else "lower"
    return f"its horn {way.past:.1f} deg past its {side} limit, {_deg(way.limit)}"


def turned_advice(name: str, servo_id: int, way: Way, lim, offset: int) -> str:
    """Why a joint whose reading counts whole turns is left holding, and
    what puts it right: the reset, where it lands in the horn's turn; else
    a hand, within its range."""
    said = (f"{name} (servo {servo_id}) reads {_deg(way.reading)} ('servoctl info {servo_id}'), "
            f"{where(way, lim)}: the reading counts {abs(way.turns)} whole turn{'s' if abs(way.turns) > 1 else ''} "
            f"{'more' if way.turns > 0 else 'less'} than where the horn is (wheel mode, multi-turn moves, or the "
            f"wrap at +-180 deg), and its targets would turn it back")
    reset = after_reset(way.reading, offset)
    if way_back(reset, lim).turns == 0:
        back = "" if way.limit is None else f", and connect() takes it {way.past:.1f} deg back to {_deg(way.limit)}"
        return (f"{said}; release it and reset its turns ('servoctl stop {servo_id}', then 'servoctl origin "
                f"{servo_id} --reset-turns': it then reads {_deg(reset)}{back}), then connect again")
    return (f"{said}; release it ('servoctl stop {servo_id}') and turn it by hand within its range, then reset "
            f"its turns ('servoctl origin {servo_id} --reset-turns') and connect again")


def can_reframe(way: Way, lim, offset: int, angle_limit_on: int, firmware: str) -> bool:
    """Whether the arm itself takes the horn the short way across the wrap
    and resets its turns there: outside its limits, a reset where it stands
    lands in the wrong turn, and one at the goal lands on the limit; this
    firmware (a reset in damping; its multi-turn targets are not clamped
    with item 48 at 1, and the goal is outside the limits)."""
    return (way.limit is not None and way.turns != 0 and firmware == "servoctl" and angle_limit_on == 1
            and way_back(after_reset(way.reading, offset), lim).turns != 0
            and after_reset(way.goal, offset) == way.limit)


def reframe(s: Servo, way: Way) -> int:
    """At the goal: its turns reset with the output damped, not let go (the
    firmware resets only an output it does not drive), and held again, the
    three back to back in one write. Returns the reading after."""
    damp, hold = (p.encode_request(p.STOP_ON_CONTROL, s.id, mode, 0) for mode in (0x12, 0x11))
    s.bus.send_burst([(p.STOP_ON_CONTROL, damp), (p.RESET_MULTI_TURN, bytes([s.id])), (p.STOP_ON_CONTROL, hold)])
    s.bus.drain()  # a reset's answer, where item 33 asks for one
    return s.multi_turn_angle()[0]
