"""An arm of named joints on one bus, for a robot framework's loop (the
LeRobot plugins in tools/lerobot_plugins; docs/lerobot.md): degrees in
and out, a frame at a time.

- Which firmware: this one (it answers item 64, the bus watchdog) or the
  maker's (it does not).
- hold_here(): torque on where each joint is; nothing moves (but a joint
  outside its angle limits, to the nearest by the short way, modulo a
  turn: arm_ramp.into_limits, arm_turns.py).
- positions(): every joint's angle from one Sync Monitor (0.1 deg), fresh
  or JointSilent naming the joints that did not answer in their slot;
  a joint whose servo released its output (supply, heat) raises
  JointFault with its fault history.
- send(): this firmware gets streamed setpoints (the servo joins them with
  a cubic, docs/streaming.md); the maker's gets angle moves in one
  SyncCommand, each timed to the frame period measured between sends.
- send(): the first targets after hold_here() ramp from where each joint
  is to what is asked at ramp_speed_deg_s (arm_ramp.py; 0: no ramp); a
  joint follows freely from the frame its target is reached.
- On this firmware the bus watchdog (items 64, 65) is armed while the arm
  is driven, and put back as it was on close; the servo's own setting is
  kept on the host meanwhile (watchdog_record.py), so a run that ended
  without putting it back is not taken for the servo's own. A servo that
  restarts mid-run (its watchdog back to off) is armed again and ramps
  from where its horn is (arm_reset.py), or from the nearest limit where
  it fell outside them (moved there first, as at connect).
- A joint that does not answer because two servos hold its ID is said to
  be shared (JointShared: scan's probe hears their answers collide).

Time is the bus's clock (the simulator's on servo_sim)."""
import logging
import math

from . import arm_calibrate
from . import protocol as p
from . import registers
from .fault_code import phrase
from .errors import NoReply, ServoError, UsageError, ValueOutOfRange
from .arm_ramp import DEFAULT_SPEED_DEG_S, Ramp, into_limits
from .arm_reset import ResetWatch
from .arm_watchdog import WATCHDOG_ACTIONS, arm_one
from .group import sync_monitor
from .servo import Servo
from .setpoints import MAX_SPEED_DECIDEG_S, Stream, put_back_period, read_limits, tell_period
from .watchdog_record import WatchdogRecords

log = logging.getLogger(__name__)

# Status bits with which the servo has let its output go (frame.toml).
RELEASED_BY = ("high_voltage", "low_voltage", "over_temperature")
# The maker's moves: the shortest and longest time fitted to the frames.
MOVE_MS = (10, 1000)


class JointSilent(NoReply):
    """A joint's servo did not answer in its slot: no stale value is given."""

    def __init__(self, message: str, joints: list):
        super().__init__(message)
        self.joints = joints


class JointShared(JointSilent):
    """Two or more servos hold a joint's ID: their answers collide."""


class JointFault(ServoError):
    """A joint's servo has let its output go: the message has its faults."""


def fault_text(servo: Servo, newest: int = 3) -> str:
    """The newest faults of the servo's history, as a phrase; what is
    known when it cannot be read (the maker's firmware keeps none)."""
    try:
        faults = servo.faults()[:newest]
    except NoReply:
        return "its fault history could not be read (no answer)"
    except ServoError:
        return "it keeps no fault history (the maker's firmware)"
    if not faults:
        return "no fault in its history"
    said = ", ".join(phrase(f) for f in faults)
    return f"its newest faults: {said} ('servoctl faults {servo.id}')"


def shared_text(bus: p.Bus, ids: list):
    """What scan's probe says of the first of ids that two or more servos
    hold (their answers collide, or come twice), or None."""
    from . import scan  # when a joint is silent only: scan reaches the update images' tools

    window = scan.reply_window_s(bus.serial.baudrate)
    for servo_id in ids:
        found = scan.probe(bus, servo_id, window)
        if found is not None and found.shared:
            return found.describe()
    return None


def detect_firmware(bus: p.Bus, servo_id: int) -> str:
    """"servoctl" (this firmware: item 64 reads) or "maker"."""
    try:
        Servo(bus, servo_id).read("watchdog_ms")
        return "servoctl"
    except NoReply:
        raise
    except ServoError:
        return "maker"



WATCHDOG_MS_MOST = registers.find("watchdog_ms").high  # item 64's range


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def check_settings(joints: dict, fps, firmware, watchdog_ms, watchdog_action, ramp_speed_deg_s) -> None:
    """An Arm's settings, refused (UsageError) before anything is written
    (a watchdog record of -1 was, then refused); the LeRobot follower's
    config checks them with these words too."""
    if not joints:
        raise UsageError("an arm needs at least one joint")
    twice = {i: [n for n, j in joints.items() if j == i] for i in set(joints.values())}
    twice = [f"{' and '.join(names)} (servo {i})" for i, names in twice.items() if len(names) > 1]
    if twice:  # one servo would be driven to two joints' targets, and read as both
        raise UsageError(f"each joint has its own servo ID: {'; '.join(twice)} share one")
    if not (_number(watchdog_ms) and isinstance(watchdog_ms, int) and 0 <= watchdog_ms <= WATCHDOG_MS_MOST):
        raise UsageError(f"watchdog_ms is 0..{WATCHDOG_MS_MOST} ms (0: left as it is), not {watchdog_ms!r}")
    if watchdog_action not in WATCHDOG_ACTIONS:
        raise UsageError(f"watchdog_action is one of {', '.join(WATCHDOG_ACTIONS)}, not {watchdog_action!r}")
    if firmware not in ("auto", "servoctl", "maker"):
        raise UsageError(f"firmware is auto, servoctl or maker, not {firmware!r}")
    if not (_number(fps) and math.isfinite(fps) and fps > 0):
        raise UsageError(f"fps is the loop's frames a second, more than 0, not {fps!r}")
    if not (_number(ramp_speed_deg_s) and ramp_speed_deg_s >= 0 and math.isfinite(ramp_speed_deg_s)):
        raise UsageError(f"ramp_speed_deg_s is 0 (no ramp) or a speed in deg/s, not {ramp_speed_deg_s!r}")


class Arm:
    """joints: {name: servo ID}. fps: the frames a second the host's loop
    sends (a stream's period). firmware: "auto", "servoctl" or "maker"
    (the maker's path runs on this firmware too: its packets are the
    maker's). watchdog_ms 0 leaves the watchdog as it is; records keeps
    each servo's own setting meanwhile (WatchdogRecords: the user's state
    folder unless given). ramp_speed_deg_s: the first targets' top speed
    from where the arm is held, deg/s; 0: none."""

    def __init__(self, bus: p.Bus, joints: dict, fps: float = 30.0, firmware: str = "auto",
                 watchdog_ms: int = 500, watchdog_action: str = "hold",
                 ramp_speed_deg_s: float = DEFAULT_SPEED_DEG_S, records: WatchdogRecords = None):
        check_settings(joints, fps, firmware, watchdog_ms, watchdog_action, ramp_speed_deg_s)
        self.bus, self.joints = bus, dict(joints)
        self.ids = list(self.joints.values())
        self.names = {i: n for n, i in self.joints.items()}
        self.period_s = 1.0 / fps
        self.firmware = firmware
        self.watchdog_ms, self.watchdog_action = watchdog_ms, watchdog_action
        self.records = records if records is not None else WatchdogRecords()
        self.ramp = Ramp(ramp_speed_deg_s, self.period_s)
        self._held_at = None  # the bus clock when hold_here held the arm
        self.limits = {}
        self.stream = None
        self.targets = {}  # {name: degrees}: the last sent, or where hold_here held
        self._before = {}  # the targets before those
        self._watchdog_before = {}  # {id: (serial, the servo's own setting)}
        self._period_before = {}  # {id: item 69 as the servo had it}
        self._times = []  # the bus clock at the last sends, up to 3
        self.measured_period_s = self.period_s
        self.frames = 0
        self.watch = None  # ResetWatch while the watchdog is armed on this firmware

    # ---- the session -------------------------------------------------
    def open(self) -> "Arm":
        """Finds the firmware and every joint's limits; arms the watchdog.
        Nothing moves, and the output is not driven yet."""
        self.positions()  # every joint answers, or JointSilent names those that do not
        if self.firmware == "auto":
            self.firmware = detect_firmware(self.bus, self.ids[0])
        self.limits = read_limits(self.bus, self.ids)
        if self.firmware == "servoctl" and self.watchdog_ms:
            self._arm_watchdog()
            self.watch = ResetWatch(self.ids, self.watchdog_ms)
        if self.firmware == "servoctl":  # told, not learned from the stamps (setpoints.tell_period)
            self._period_before = tell_period(self.bus, self.ids, self._period_ms())
        return self

    def _period_ms(self) -> int:
        return max(1, round(self.period_s * 1000))

    def _arm_watchdog(self) -> None:
        for servo_id in self.ids:
            self._arm_one(servo_id)

    def _arm_one(self, servo_id: int) -> None:
        ours = (self.watchdog_ms, WATCHDOG_ACTIONS[self.watchdog_action])
        kept = arm_one(Servo(self.bus, servo_id), f"{self.names[servo_id]} (servo {servo_id})", self.records, ours)
        if kept is not None:
            self._watchdog_before[servo_id] = kept
        self.limits[servo_id].watchdog_ms = self.watchdog_ms

    def _again(self, servo_id: int, ms: int) -> None:
        """A servo that restarted (arm_reset.py): armed again, held where
        its horn is (outside its limits: moved to the nearest, into_limits),
        and its joint ramped from there."""
        name = self.names[servo_id]
        self._arm_one(servo_id)
        Servo(self.bus, servo_id).write("stream_period_ms", self._period_ms())  # lost with its RAM
        Servo(self.bus, servo_id).stop("hold")
        state = sync_monitor(self.bus, [servo_id]).get(servo_id)
        if state is None:
            raise JointSilent(f"{name} (servo {servo_id}) restarted and then did not answer: no target is sent", [name])
        here = state.angle_decideg / 10.0
        # Fallen outside its limits: to the nearest first, as at connect (a setpoint outside is clamped: a jump).
        held = into_limits(self, {name: here}, self.ramp.speed_deg_s or DEFAULT_SPEED_DEG_S, restarted=True)[name]
        log.warning("%s (servo %d): its bus watchdog read %d ms, not the arm's %d ms: it restarted (its supply or "
                    "its connector?) or another program set it; armed again, held at %.1f deg%s, and ramped from "
                    "there", name, servo_id, ms, self.watchdog_ms, here,
                    "" if held == here else f" (outside its angle limits: moved to the nearest, {held:.1f} deg)")
        self.targets[name] = held
        self._before.pop(name, None)
        self.ramp.again(name)
        self.stream.restart(servo_id)

    def hold_here(self) -> dict:
        """Torque on where every joint is (StopOnControlMode's hold: no
        target, so nothing moves); the first target is that pose, within
        the angle limits (a joint outside goes to the nearest first, the
        short way). One whose reading counts whole turns that a reset puts
        right (after wheel mode) is refused, left holding: its targets are
        taken in its limits' turn, and the first would turn it back."""
        for servo_id in self.ids:
            Servo(self.bus, servo_id).stop("hold")
        here = self.positions()
        # One outside its limits goes to the nearest first: the ramp starts where the servo takes a setpoint.
        self.targets, self._before = into_limits(self, here, self.ramp.speed_deg_s or DEFAULT_SPEED_DEG_S), {}
        self.ramp.start(here)
        self._held_at = self.bus.clock()
        if self.firmware == "servoctl":
            self.stream = Stream(self.bus, self.ids, self.period_s, self.limits)
        self._times = []
        return dict(self.targets)

    def close(self, release: bool = True) -> None:
        """Releases the joints (or leaves them holding) and puts each
        watchdog back as it was."""
        errors = []
        if release:
            for servo_id in self.ids:
                Servo(self.bus, servo_id).stop("release")
        for servo_id, (serial, (ms, action)) in self._watchdog_before.items():
            try:
                s = Servo(self.bus, servo_id)
                s.write("watchdog_ms", ms)
                s.write("watchdog_action", action)
                self.records.forget(serial, self.bus.port)  # kept where it could not be put back
            except (ServoError, OSError) as e:  # the next servos' still put back
                errors.append(f"{self.names[servo_id]}: {e}")
        self._watchdog_before = {}
        put_back_period(self.bus, self._period_before)
        self._period_before = {}
        self.stream = None
        if errors:  # after an error that said why (a servo gone): this says what it leaves
            raise ServoError("on disconnect, the bus watchdog this connection set stays on "
                             + "; ".join(errors) + ": it is on record, and the next connect puts it back")

    # ---- calibration (this firmware: stored on the servos) -------------
    def set_zero_here(self) -> dict:
        """Each joint's zero here, its range kept (arm_calibrate.set_zero_here)."""
        return arm_calibrate.set_zero_here(self)

    def store_ranges(self, ranges: dict) -> None:
        """{name: (lowest, highest) deg} stored as each servo's angle limits
        (arm_calibrate.store_ranges)."""
        arm_calibrate.store_ranges(self, ranges)
        self.limits = read_limits(self.bus, self.ids)

    def ranges_stored(self) -> bool:
        return arm_calibrate.ranges_stored(self.limits)

    # ---- a frame -----------------------------------------------------
    def positions(self) -> dict:
        """{name: degrees} from one Sync Monitor, 0.1 deg; JointSilent or
        JointFault rather than an old value."""
        states = sync_monitor(self.bus, self.ids)
        silent = [i for i in self.ids if i not in states]
        if silent:
            if self.watch is not None:
                self.watch.went_silent(silent)  # restarting? read every frame until it answers
            named = ", ".join(f"{self.names[i]} (servo {i})" for i in silent)
            names = [self.names[i] for i in silent]
            shared = shared_text(self.bus, silent)
            if shared is not None:  # not a cable: two servos answer at once and garble each other
                raise JointShared(f"{named} did not answer in the Sync Monitor: {shared}; no position is "
                                  f"given", names)
            if not states:  # none at all: the link's rate or the IDs, more likely than every cable
                baud = self.bus.serial.baudrate
                raise JointSilent(f"no joint answered: {named}; no position is given (is the arm powered, "
                                  f"are its servos at these IDs and at {baud} baud, as the bus is? a new "
                                  f"servo is at ID 0 and 115200 baud)", names)
            one = len(silent) == 1
            raise JointSilent(f"{named} did not answer in {'its slot' if one else 'their slots'} of the Sync "
                              f"Monitor: no position is given for {'it' if one else 'them'} (is it powered, its "
                              f"cable in? {fault_text(Servo(self.bus, silent[0]))})", names)
        for servo_id, m in states.items():
            released = [b for b in registers.status_names(m.status) if b in RELEASED_BY]
            if released:
                raise JointFault(f"{self.names[servo_id]} (servo {servo_id}) has released its output "
                                 f"({', '.join(released)}); {fault_text(Servo(self.bus, servo_id))}")
        self.frames += 1
        return {self.names[i]: states[i].angle_decideg / 10.0 for i in self.ids}

    def clamp(self, targets: dict) -> dict:
        """targets ({name: degrees}) within what each servo takes from the
        last target in one frame: its angle limits, and its top speed
        (750 deg/s) over a frame period. Not rounded: the packets carry
        0.1 deg, and the speeds come from the targets as asked."""
        out = {}
        step = (MAX_SPEED_DECIDEG_S - 100) / 10.0 * self.period_s  # 10 deg/s short of it: rounding
        for name, deg in targets.items():
            lim = self.limits[self.joints[name]]
            deg = float(deg)
            if not math.isfinite(deg):  # a policy's NaN or inf: refused, never "to the limit"
                raise ValueOutOfRange(f"{name}: a target takes a finite number of degrees, not {deg}")
            if lim.angle_min is not None:
                deg = min(max(deg, lim.angle_min / 10.0), lim.angle_max / 10.0)
            last = self.targets.get(name)
            if last is not None and self.firmware == "servoctl":
                deg = min(max(deg, last - step), last + step)
            out[name] = deg
        return out

    def send(self, targets: dict) -> dict:
        """Every joint's next target (a missing one keeps its last); returns
        what was sent, clamped as clamp() does."""
        unknown = sorted(set(targets) - set(self.joints))
        if unknown:
            raise UsageError(f"no joint named {', '.join(unknown)} (the arm's: {', '.join(self.joints)})")
        if not self.targets:
            raise UsageError("hold_here() first: the arm's first target is where it is")
        now = self.bus.clock()
        since = now - (self._times[-1] if self._times else self._held_at)
        sent = self.ramp.step(self.clamp({**self.targets, **targets}), self.targets, since, set(targets))
        if self._times:
            # The frame period as the host keeps it: the maker's moves are fitted to it.
            self.measured_period_s += 0.3 * (min(now - self._times[-1], 1.0) - self.measured_period_s)
        self._times = (self._times + [now])[-3:]
        if self.firmware == "servoctl":
            # Stamped now: a target is where the arm should be when it was
            # sent, and the servo plays it at that moment's place.
            self.stream.send({self.joints[n]: d for n, d in sent.items()}, self._velocities(sent), at_s=now)
        else:
            self._send_moves(sent)
        self._before = self.targets
        self.targets = sent
        if self.watch is not None:  # after the setpoints: their times are the frames'
            for servo_id, ms in self.watch.restarted(self.bus, self.measured_period_s):
                self._again(servo_id, ms)
        return {n: round(d, 1) for n, d in sent.items()}

    def _velocities(self, sent: dict) -> dict:
        """{id: deg/s} at each new setpoint, from the last three and the
        times they were sent (a host's frames come a few ms early or late,
        and a speed from the nominal period would be off by as much): the
        second-order backward difference, the speed at the newest (the
        first-order one gives it half a frame late, and each segment would
        end at a speed the next must correct); 0 after a hold; within the
        servo's top speed."""
        top = (MAX_SPEED_DECIDEG_S - 100) / 10.0
        out = {}
        t = self._times
        for name, deg in sent.items():
            last, before = self.targets.get(name), self._before.get(name)
            if len(t) < 2 or last is None:
                v = 0.0
            elif len(t) < 3 or before is None:
                v = (deg - last) / max(t[-1] - t[-2], 1e-3)
            else:
                h1, h2 = max(t[-1] - t[-2], 1e-3), max(t[-2] - t[-3], 1e-3)
                v = (deg * (2 * h1 + h2) / (h1 * (h1 + h2)) - last * (h1 + h2) / (h1 * h2)
                     + before * h1 / (h2 * (h1 + h2)))
            out[self.joints[name]] = min(max(v, -top), top)
        return out

    def _send_moves(self, sent: dict) -> None:
        """The maker's protocol: one SyncCommand of MoveOnAngleMode, each move
        as long as a frame, so it ends as the next begins."""
        ms = min(max(round(self.measured_period_s * 1000), MOVE_MS[0]), MOVE_MS[1])
        records = b"".join(p.encode_request(p.ANGLE, self.joints[n], round(d * 10), ms, 0) for n, d in sent.items())
        self.bus.send(p.SYNC, bytes([p.ANGLE, len(records) // len(sent), len(sent)]) + records)

