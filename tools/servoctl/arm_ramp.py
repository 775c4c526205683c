"""The first targets of an arm's loop (servoctl.arm), from where it was
held to what the loop asks: a leader that stands away from the follower
is not a target to jump to (a target may move 740 deg/s a frame; a 34 deg
jump in two frames in a recorded episode); nor is a joint resting outside
its angle limits a start the servo takes (into_limits). Degrees and
seconds."""
import math

from .arm_turns import can_reframe, reframe, turned_advice, way_back
from .checks import to_ms
from .errors import ServoError, UsageError
from .move_request import MoveRequest
from .servo import Servo

DEFAULT_SPEED_DEG_S = 45.0  # a 34 deg gap to a leader's pose takes a second
RISE_S = 0.25  # from rest to the ramp's speed


class Ramp:
    """Each joint's target moves from where it was held toward what is
    asked at up to speed_deg_s: up to that speed in RISE_S, slowing down to
    arrive with the target's own speed (a step from rest, or to rest, jolts
    the horn to twice the speed), over the time since the last send, a
    frame period at most (a late frame is no licence to jump). A joint
    whose target is within that step is there, and follows freely from
    then: a leader that moves slower than the ramp is caught up. Only a
    joint asked for leaves the ramp: one left out of an action keeps its
    target where it is, and ramps when it is asked. A speed of 0: no
    ramp."""

    def __init__(self, speed_deg_s: float, period_s: float):
        self.speed_deg_s, self.period_s = speed_deg_s, period_s
        self.joints = set()  # the joints whose targets still ramp to what is asked
        self._speeds, self._asked = {}, {}  # {name: deg/s of its last step}, {name: deg asked last}

    def start(self, names) -> None:
        """The arm is held where it is: every joint ramps from there."""
        self.joints = set(names) if self.speed_deg_s > 0 else set()
        self._speeds, self._asked = {}, {}

    def again(self, name: str) -> None:
        """The joint ramps again from rest, from its last target (its
        servo restarted: the target is where its horn is)."""
        if self.speed_deg_s > 0:
            self.joints.add(name)
        self._speeds.pop(name, None)
        self._asked.pop(name, None)

    def step(self, wanted: dict, last: dict, since_s: float, asked=None) -> dict:
        """wanted ({name: deg}) as far as the ramp lets each joint go from
        last (its last target) in since_s, the time since that was sent;
        asked: the joints the action named (None: all of wanted)."""
        if not self.joints:
            return wanted
        dt = min(max(since_s, 0.0), self.period_s)
        top, accel = self.speed_deg_s, self.speed_deg_s / RISE_S
        out = dict(wanted)
        for name in list(self.joints):
            if asked is not None and name not in asked:
                out[name] = last[name]  # where it is, still ramping: not asked, so not reached
                self._speeds[name] = 0.0
                continue
            speed, gap = self._speeds.get(name, 0.0), wanted[name] - last[name]
            moving = (wanted[name] - self._asked.get(name, wanted[name])) / since_s if since_s > 0 else 0.0
            goal = min(max(moving + math.copysign(math.sqrt(2 * accel * abs(gap)), gap), -top), top)
            speed += min(max(goal - speed, -accel * dt), accel * dt)
            if abs(gap) <= abs(speed * dt) and speed * gap >= 0:
                self.joints.discard(name)  # there: from now on it follows
            else:
                out[name] = last[name] + speed * dt
                self._speeds[name] = speed
            self._asked[name] = wanted[name]
        return out


def within(deg: float, lim) -> float:
    """deg within a servo's angle limits (setpoints.Limits), if they are on."""
    return deg if lim.angle_min is None else min(max(deg, lim.angle_min / 10.0), lim.angle_max / 10.0)


def into_limits(arm, here: dict, speed_deg_s: float, restarted: bool = False) -> dict:
    """here ({name: deg}, where arm's joints are held) within their limits:
    a joint outside them (it rests a hair past one, or was pushed far out)
    is moved to the nearest by the short way (arm_turns.way_back: 188 deg
    is 12.8 past 175.2, not 135.1 below -36.9) at up to speed_deg_s and
    waited for, on the bus's clock, a Sync Monitor a frame (which feeds
    every bus watchdog); its setpoints, and the ramp, then start there, as
    the servo takes them (it clamps a streamed setpoint to its limits: one
    outside is a jump). One whose reading is a turn off where its horn
    stands (reads -172 for 188) goes the short way across the wrap, and its
    turns are reset there (arm_turns.reframe); one that counts whole turns
    a reset puts right is refused (UsageError, left holding), saying so.
    A refusal outside the limits (arm.limits) then advises as for an arm
    whose limits are its calibration, not to switch them off. restarted:
    here is one joint whose servo restarted mid-run (arm_reset.py: it fell
    while its output was released), and the error says so; the other
    joints hold their last setpoints meanwhile (a stream a period late
    brakes to a hold)."""
    for lim in arm.limits.values():  # its range, as calibrated: never to be switched off to get by
        lim.advice = ("The arm keeps its targets within the limits read at connect: were they changed since? "
                      "Connect again (calibrate again to change them)")
    ways, turned = {}, []
    for name, deg in here.items():
        servo_id, lim = arm.joints[name], arm.limits[arm.joints[name]]
        ways[name] = way = way_back(round(deg * 10), lim)
        if way.turns:
            s = Servo(arm.bus, servo_id)
            offset = s.read("center_offset")
            if not can_reframe(way, lim, offset, s.read("angle_limit_on"), arm.firmware):
                turned.append(turned_advice(name, servo_id, way, lim, offset))
    if turned:  # its targets are taken in its limits' turn: the first would turn it back
        raise UsageError("; ".join(turned))
    held = {n: d if ways[n].limit is None else ways[n].limit / 10 for n, d in here.items()}
    out = {n: w.goal / 10 for n, w in ways.items() if w.limit is not None}  # in the reading's turn
    soft = 0.0  # the first move after power-up lasts the soft-start time (items 49, 50): a restart's does
    for name, deg in out.items():
        s = Servo(arm.bus, arm.joints[name])
        soft = max(soft, s.read("soft_start_time") / 1000.0 if s.read("soft_start_on") else 0.0)
        if ways[name].turns:  # beyond the limits in the reading's frame, which the servo's check refuses
            ramp = to_ms(RISE_S, "accel_s")
            s.send_move(ways[name].goal, MoveRequest(ramp, ramp, velocity=round(speed_deg_s * 10), multi_turn=True))
        else:  # past +-180 (188 deg, 0 turns) a single-turn target is taken a turn up: multi-turn there
            s.move_to(deg, speed_dps=speed_deg_s, accel_s=RISE_S, decel_s=RISE_S,
                      multi_turn=not -180 <= here[name] < 180)
    start = arm.bus.clock()
    end = start + 2.0 * max((abs(here[n] - d) for n, d in out.items()), default=0) / speed_deg_s + soft + 2.0

    def there(name, deg):  # within its limits, or a reading off, in the reading's turn
        lim, deg = arm.limits[arm.joints[name]], deg - ways[name].turns * 360.0
        return abs(within(deg, lim) - deg) <= 0.1

    while out and not all(there(n, d) for n, d in arm.positions().items() if n in out):
        if arm.bus.clock() > end and restarted:
            name = next(iter(out))
            lim = arm.limits[arm.joints[name]]
            raise ServoError(f"{name} (servo {arm.joints[name]}) restarted mid-run (its supply or its connector?) "
                             f"and came back at {here[name]:.1f} deg, outside its angle limits "
                             f"({lim.angle_min / 10:.1f}..{lim.angle_max / 10:.1f} deg), and did not reach the "
                             f"nearest within {end - start:.1f} s (blocked?): it holds where it is; move it "
                             f"within its range and connect again")
        if arm.bus.clock() > end:
            raise ServoError(f"{', '.join(out)}: outside its angle limits, and not at the nearest within "
                             f"{end - start:.1f} s (blocked?): move it within its range and connect again")
        arm.bus.sleep(arm.period_s)
    for name, way in ways.items():
        if way.turns:  # at the limit a turn off: its reading put in the limits' turn
            servo_id = arm.joints[name]
            now = reframe(Servo(arm.bus, servo_id), way)
            if abs(now - way.limit) > 5:
                raise ServoError(f"{name} (servo {servo_id}): its turns reset at {way.goal / 10:.1f} deg, it reads "
                                 f"{now / 10:.1f} deg, not {way.limit / 10:.1f}: it holds where it is; connect again")
            held[name] = now / 10
    return held
