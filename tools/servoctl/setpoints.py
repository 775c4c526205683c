"""A stream's setpoints (StreamSetpoint, 0x45; docs/streaming.md): Stream
sends them, one per servo per period; RobotLoop is a robot's whole cycle
(one SyncCommand of setpoints, one Sync Monitor) with its rate against
the wire's.

Every setpoint is checked against what its servo allows before it is sent
(Limits, read from the servo): its angle limits when they are on, and the
servo's top speed (750 deg/s) between one setpoint and the next. One out of
them is refused, never clamped: a clamped path is not the host's, and the
servo, without the next setpoint, brakes to a hold where the last one
was (docs/streaming.md). A file is checked whole before anything moves.

A stream feeds each servo's bus watchdog (item 64) once a period: a period
longer than half its watchdog_ms is refused before anything is sent (the
servo would take its watchdog_action between setpoints)."""
import math
import struct
from dataclasses import dataclass

from . import protocol as p
from . import registers
from .checks import check_range, scaled
from .errors import NoReply, ServoError, UsageError, ValueOutOfRange
from .group import MAX_SYNC_RECORDS, monitor_answers, monitor_request
from .loop_rate import LoopRate, check_wire, cycle_bytes, warn_late, wire_limit_hz

# The ranges of StreamSetpoint's angle (multi-turn, as ReadMultiTurnAngle)
# and velocity, +-: the firmware clamps beyond (protocol/servo_schema).
MAX_ANGLE_DECIDEG = p.field_range(p.STREAM_SETPOINT, "angle")[1]
MAX_SPEED_DECIDEG_S = p.field_range(p.STREAM_SETPOINT, "velocity")[1]
PERIOD_RANGE_MS = (1, registers.find("stream_period_ms").high)  # item 69's, but for its 0 (off)


def check_ids(ids) -> list:
    ids = list(ids)
    if not ids or len(ids) > MAX_SYNC_RECORDS:
        raise UsageError(f"a stream takes 1..{MAX_SYNC_RECORDS} servos, not {len(ids)}")
    for servo_id in ids:
        check_range("servo ID", servo_id, 0, p.MAX_ID)
    twice = sorted({i for i in ids if ids.count(i) > 1})
    if twice:
        raise UsageError(f"servo {', '.join(map(str, twice))} is listed more than once")
    return ids


@dataclass
class Limits:
    """What one servo allows a streamed setpoint, 0.1 deg and 0.1 deg/s:
    angle_min..angle_max if its angle limits are on (items 48, 51, 52),
    else None; the top speed, the servo's own clamp for moves and
    setpoints (docs/streaming.md), between a setpoint and the next; and its
    bus watchdog's watchdog_ms (item 64, ms; 0 off), which a stream's
    period must keep fed. advice: what a refusal outside the angle limits
    advises, if not to change them or turn them off (a calibrated arm's)."""
    angle_min: int = None
    angle_max: int = None
    speed: int = MAX_SPEED_DECIDEG_S
    watchdog_ms: int = 0
    advice: str = None

    @classmethod
    def of(cls, cfg: dict) -> "Limits":
        """From a servo's user area (servo.Servo.read_all) and, where
        read_configs found it, its watchdog_ms."""
        watchdog_ms = cfg.get("watchdog_ms", 0)
        if not cfg["angle_limit_on"]:
            return cls(watchdog_ms=watchdog_ms)
        return cls(cfg["angle_min"], cfg["angle_max"], watchdog_ms=watchdog_ms)

    def check_period(self, servo_id: int, period_ms: int) -> str:
        """Why a stream at period_ms would starve this servo's bus watchdog,
        or "". A stream feeds it once a period (the setpoints and the Sync
        Monitor, back to back), so the period must be at most half
        watchdog_ms: a cycle late by up to a period (the host's jitter, the
        wire's time, a lost frame) still feeds it in time."""
        if not self.watchdog_ms or 2 * period_ms <= self.watchdog_ms:
            return ""
        longer = 2 * period_ms
        return (f"servo {servo_id}'s bus watchdog (watchdog_ms {self.watchdog_ms} ms) would act between "
                f"setpoints {period_ms} ms apart: a stream feeds it once a period, and the period must be at "
                f"most half watchdog_ms ({self.watchdog_ms // 2} ms) to allow for the wire and the host's "
                f"jitter. Use a period of at most {self.watchdog_ms // 2} ms, or a longer watchdog "
                f"('servoctl config set {servo_id} watchdog_ms {longer}', or 0 for off)")

    def check(self, servo_id: int, angle: int, last: int = None, period_ms: int = 0, velocity: int = 0) -> str:
        """Why the setpoint angle (after last, a period_ms earlier; at
        velocity) is refused, or "" if it is not."""
        if self.angle_min is not None and not self.angle_min <= angle <= self.angle_max:
            return (f"servo {servo_id} limits its angle to {self.angle_min / 10:.1f}..{self.angle_max / 10:.1f} deg "
                    f"(angle_min, angle_max, angle_limit_on): a setpoint of {angle / 10:.1f} deg is outside them. "
                    + (self.advice or f"Change the limits, or turn them off with 'servoctl config set {servo_id} "
                                      f"angle_limit_on 0'"))
        if last is not None and abs(angle - last) * 1000 > self.speed * period_ms:
            return (f"servo {servo_id}: {abs(angle - last) / 10:.1f} deg in {period_ms} ms (from {last / 10:.1f} to "
                    f"{angle / 10:.1f} deg) is {abs(angle - last) * 100 / period_ms:.0f} deg/s, beyond the "
                    f"{self.speed / 10:.0f} deg/s the servo moves")
        if abs(velocity) > self.speed:
            return (f"servo {servo_id}: a velocity of {velocity / 10:g} deg/s is beyond the {self.speed / 10:.0f} "
                    f"deg/s the servo moves")
        return ""


def read_configs(bus: p.Bus, ids) -> dict:
    """{id: the servo's user area, one ReadBatchData each, and its
    watchdog_ms (item 64; 0 where the servo has none)}."""
    from .servo import Servo

    out = {}
    for servo_id in ids:
        s = Servo(bus, servo_id)
        try:
            out[servo_id] = s.read_all()
        except NoReply as e:
            raise NoReply(f"{e}: is servo {servo_id} on the bus, at this baud rate? Nothing was sent") from None
        try:  # item 64, outside the user area: this firmware's, the maker's has none
            out[servo_id]["watchdog_ms"] = s.read("watchdog_ms")
        except ServoError:
            out[servo_id]["watchdog_ms"] = 0
    return out


def tell_period(bus: p.Bus, ids, period_ms: int) -> dict:
    """Item 69 (stream_period_ms) set on each servo to the host's period:
    the servo places every setpoint 3/2 of it after its stamp from the
    first, not after learning it from the stamps' steps (a host's jitter,
    +-10 ms at 60 Hz, made the steps it learned from short, and a late
    frame then stopped the stream). {id: the value before}, for
    put_back_period."""
    from .servo import Servo

    before = {}
    for servo_id in ids:
        before[servo_id] = Servo(bus, servo_id).read("stream_period_ms")
        Servo(bus, servo_id).write("stream_period_ms", period_ms)
    return before


def put_back_period(bus: p.Bus, before: dict) -> None:
    """Item 69 as each servo had it (a RAM item: a power-up clears it);
    a servo gone is left, the error that said so is its caller's."""
    from .servo import Servo

    for servo_id, ms in before.items():
        try:
            Servo(bus, servo_id).write("stream_period_ms", ms)
        except (ServoError, OSError):
            pass


def read_limits(bus: p.Bus, ids) -> dict:
    """{id: Limits} read from each servo."""
    return {servo_id: Limits.of(cfg) for servo_id, cfg in read_configs(bus, ids).items()}


class Stream:
    """Setpoints for ids every period_s: send({id: degrees}) once a period,
    each stamped with the moment it is for (at_s, or its place on the
    period's grid); a servo plays it 3/2 period after a punctual send
    (docs/streaming.md, "On the host's timeline"). Velocities, in degrees per second,
    are given or taken from the last two setpoints. One servo gets its own
    packet; several, one SyncCommand frame, so they start together.

    limits, {id: Limits}, are read from the servos if not given: a send
    with a setpoint outside its servo's angle limits, a step from the last
    setpoint faster than the servo moves, or a velocity beyond it, raises
    ValueOutOfRange and sends nothing. A period longer than half a
    servo's watchdog_ms (in the limits: read ones have it, given ones say
    it or 0) raises UsageError when the Stream is made: a loop at that
    period would starve the watchdog by design."""

    def __init__(self, bus: p.Bus, ids, period_s: float, limits: dict = None):
        self.bus = bus
        self.ids = check_ids(ids)
        self.period_ms = check_range("period", scaled(period_s, 1000, "period_s"), *PERIOD_RANGE_MS, "ms")
        self.limits = read_limits(bus, self.ids) if limits is None else {i: limits[i] for i in self.ids}
        check_period(self.limits, self.period_ms)
        self.sent = 0
        self._last = {}
        # Every record of a send in one pack: a robot's loop builds this
        # frame each cycle, between a state's arrival and the next write.
        record = p.request_format(p.STREAM_SETPOINT)
        self._records = struct.Struct(record[0] + record[1:] * len(self.ids))

    def frame_content(self, targets: dict, velocities: dict = None, at_s: float = None) -> tuple:
        """(code, content) of the next send: checks every value first. at_s:
        the moment on the host's clock (s) the setpoints are for, their
        stamp; else the send's place on the period's grid. The servo plays
        each at its stamp's place, 3/2 period after a punctual send
        (docs/streaming.md, "On the host's timeline")."""
        missing = [i for i in self.ids if i not in targets]
        if missing or len(targets) != len(self.ids):
            raise UsageError(f"a setpoint for every streamed servo ({self.ids}), not for {sorted(targets)}")
        stamp = (self.sent * self.period_ms if at_s is None else round(at_s * 1000)) % 65536
        records = []
        for servo_id in self.ids:
            angle = check_range("angle", scaled(targets[servo_id], 10, "degrees"),
                                -MAX_ANGLE_DECIDEG, MAX_ANGLE_DECIDEG, "deg", 10)
            last = self._last.get(servo_id)
            if velocities is not None:
                speed = scaled(velocities[servo_id], 10, "velocity")
            elif last is not None:
                speed = round((angle - last) * 1000 / self.period_ms)
            else:
                speed = 0
            why = self.limits[servo_id].check(servo_id, angle, last, self.period_ms, speed)
            if why:
                raise ValueOutOfRange(f"{why}: nothing of this send was sent")
            records.append((servo_id, angle, speed))
        for servo_id, angle, _ in records:
            self._last[servo_id] = angle
        code = p.STREAM_SETPOINT
        body = self._records.pack(*(v for r in records for v in (*r, stamp)))
        if len(records) == 1:
            return code, body
        return p.SYNC, bytes([code, len(body) // len(records), len(records)]) + body

    def restart(self, servo_id: int) -> None:
        """The servo restarted (servoctl.arm_reset): its next setpoint
        follows none, and is not checked against the last."""
        self._last.pop(servo_id, None)

    def send(self, targets: dict, velocities: dict = None, then=(), at_s: float = None) -> None:
        """The setpoints (stamped at_s, frame_content), and the requests then
        (code, content) after them in the same burst."""
        self.bus.send_burst([self.frame_content(targets, velocities, at_s), *then])
        self.sent += 1


class RobotLoop:
    """A robot's cycle at its period: setpoints to every servo (one
    SyncCommand of StreamSetpoint) and every servo's state back (one Sync
    Monitor). A period the wire cannot carry (check_wire) is refused when
    the loop is made; cycle() waits, on the bus's clock, until its cycle is
    due, and warns (LoopLate, with the wire's limit) when one begins a
    period or more late. pace=False runs the cycles as fast as the bus
    goes (a benchmark of the wire; stream_file keeps its own time).
    cycle() returns {id: Monitor}; rate() compares the cycles run with the
    wire's limit, every byte of both frames and of the answers back to back."""

    def __init__(self, bus: p.Bus, ids, period_s: float, limits: dict = None, pace: bool = True):
        self.stream = Stream(bus, ids, period_s, limits)
        if pace:
            check_wire(self.stream.ids, period_s, bus.serial.baudrate)
        self.bus, self.period_s, self.pace = bus, period_s, pace
        self.cycles = 0
        self.started = self.last_start = None
        self.due = None
        self.late = 0       # cycles that began a period or more after they were due
        self.missed = 0
        self.arrivals = {}  # {id: the bus clock when its last state arrived}
        self._monitor = monitor_request(self.stream.ids)

    def cycle_bytes(self) -> int:
        return cycle_bytes(self.stream.ids)

    def _wait_turn(self) -> None:
        now = self.bus.clock()
        if self.due is None:
            self.started = self.due = now
        elif now > self.due:  # on the period's grid: the next slot, never two cycles back to back
            if now - self.due >= self.period_s:
                self.late += 1
                warn_late(self.cycles + 1, now - self.due, self.period_s, self.rate(), self.bus.serial.baudrate)
            self.due += math.ceil((now - self.due) / self.period_s - 1e-9) * self.period_s
        if now < self.due:
            self.bus.sleep(self.due - now)
        self.due += self.period_s

    def cycle(self, targets: dict, velocities: dict = None, at_s: float = None) -> dict:
        """at_s: the moment the setpoints are for (Stream.frame_content); a
        paced loop's is its slot on the period's grid, a late cycle's too."""
        if self.pace:
            self._wait_turn()
            at_s = self.due - self.period_s if at_s is None else at_s
        elif self.started is None:
            self.started = self.bus.clock()
        self.last_start = self.bus.clock()
        # One write: the Sync Monitor follows the setpoints on the wire
        # without a host's gap between them.
        self.stream.send(targets, velocities, then=[self._monitor], at_s=at_s)
        states = monitor_answers(self.bus, self.stream.ids, arrivals=self.arrivals)
        self.missed += len(self.stream.ids) - len(states)
        self.cycles += 1
        return states

    def rate(self) -> LoopRate:
        """Cycles a second from the first cycle's start to the last's: N
        cycles span N - 1 periods (N over the time to the last one's end
        gave a 1 Hz file of 4 rows as 1.3 Hz)."""
        if self.started is None:
            return LoopRate(0, 0.0, wire_limit_hz(self.stream.ids, self.bus.serial.baudrate))
        if self.cycles >= 2 and self.last_start > self.started:  # seconds: N periods' worth
            seconds = (self.last_start - self.started) * self.cycles / (self.cycles - 1)
        else:
            seconds = self.bus.clock() - self.started
        return LoopRate(self.cycles, seconds, wire_limit_hz(self.stream.ids, self.bus.serial.baudrate))


def check_period(limits: dict, period_ms: int, where: str = "") -> None:
    """A stream at period_ms against every servo's watchdog_ms (Limits.check_period):
    refused, UsageError, before anything is sent."""
    for servo_id, lim in limits.items():
        why = lim.check_period(servo_id, period_ms)
        if why:
            raise UsageError(f"{where}{why}; nothing was sent")
