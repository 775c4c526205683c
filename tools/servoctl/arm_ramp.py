"""The first targets of an arm's loop (servoctl.arm), from where it was
held to what the loop asks: a leader that stands away from the follower
is not a target to jump to (a target may move 740 deg/s a frame; a 34 deg
jump in two frames in a recorded episode). Degrees and seconds."""
import math

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
