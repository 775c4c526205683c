"""Streamed setpoints (StreamSetpoint, 0x45; docs/streaming.md): a host's
trajectory, one setpoint per servo per period, which each servo
interpolates at its 1 kHz tick. Stream sends them; RobotLoop is a robot's
whole cycle (one SyncCommand of setpoints, one Sync Monitor) with its rate
against the wire's; stream_file runs a CSV trajectory and reports how
closely the servos followed it.

Every setpoint is checked against what its servo allows before it is sent
(Limits, read from the servo): its angle limits when they are on, and the
servo's top speed (750 deg/s) between one setpoint and the next. One out of
them is refused, never clamped: a clamped path is not the host's, and the
servo, without the next setpoint, brakes to a hold where the last one
was (docs/streaming.md). A file is checked whole before anything moves.

A stream feeds each servo's bus watchdog (item 64) once a period: a period
longer than half its watchdog_ms is refused before anything is sent (the
servo would take its watchdog_action between setpoints)."""
import csv
import math
import struct
from dataclasses import dataclass

from . import protocol as p
from .checks import check_range, scaled, to_ms
from .frame import jerk_limit
from .errors import NoReply, Refused, ServoError, UsageError, ValueOutOfRange
from .group import MAX_SYNC_RECORDS, monitor_answers, monitor_request, sync_monitor
from .loop_rate import (BITS_PER_BYTE, LoopLate, LoopRate, check_wire, cycle_bytes,  # noqa: F401
                        warn_late, wire_limit_hz)
from .move_request import MoveRequest
from .outcome import EXECUTING, INHIBITING, STALL, TOLERANCE_DEG

MAX_ANGLE_DECIDEG = 3686400    # the multi-turn range (ReadMultiTurnAngle)
MAX_SPEED_DECIDEG_S = 7500     # the firmware clamps beyond (schema.toml)
PERIOD_RANGE_MS = (1, 1000)    # item 69's


def _check_ids(ids) -> list:
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
    period must keep fed."""
    angle_min: int = None
    angle_max: int = None
    speed: int = MAX_SPEED_DECIDEG_S
    watchdog_ms: int = 0

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
                    f"Change the limits, or turn them off with 'servoctl config set {servo_id} angle_limit_on 0'")
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


def read_limits(bus: p.Bus, ids) -> dict:
    """{id: Limits} read from each servo."""
    return {servo_id: Limits.of(cfg) for servo_id, cfg in read_configs(bus, ids).items()}


class Stream:
    """Setpoints for ids every period_s: send({id: degrees}) once a period,
    one period ahead of where the servos should be (each servo reaches a
    setpoint a period after it arrives). Velocities, in degrees per second,
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
        self.ids = _check_ids(ids)
        self.period_ms = check_range("period", scaled(period_s, 1000, "period_s"), *PERIOD_RANGE_MS, "ms")
        self.limits = read_limits(bus, self.ids) if limits is None else {i: limits[i] for i in self.ids}
        check_period(self.limits, self.period_ms)
        self.sent = 0
        self._last = {}
        # Every record of a send in one pack: a robot's loop builds this
        # frame each cycle, between a state's arrival and the next write.
        record = p.request_format(p.STREAM_SETPOINT)
        self._records = struct.Struct(record[0] + record[1:] * len(self.ids))

    def frame_content(self, targets: dict, velocities: dict = None) -> tuple:
        """(code, content) of the next send: checks every value first."""
        missing = [i for i in self.ids if i not in targets]
        if missing or len(targets) != len(self.ids):
            raise UsageError(f"a setpoint for every streamed servo ({self.ids}), not for {sorted(targets)}")
        stamp = (self.sent * self.period_ms) % 65536
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

    def send(self, targets: dict, velocities: dict = None, then=()) -> None:
        """The setpoints, and the requests then (code, content) after them
        in the same burst."""
        self.bus.send_burst([self.frame_content(targets, velocities), *then])
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
        self.started = None
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

    def cycle(self, targets: dict, velocities: dict = None) -> dict:
        if self.pace:
            self._wait_turn()
        elif self.started is None:
            self.started = self.bus.clock()
        # One write: the Sync Monitor follows the setpoints on the wire
        # without a host's gap between them.
        self.stream.send(targets, velocities, then=[self._monitor])
        states = monitor_answers(self.bus, self.stream.ids, arrivals=self.arrivals)
        self.missed += len(self.stream.ids) - len(states)
        self.cycles += 1
        return states

    def rate(self) -> LoopRate:
        seconds = self.bus.clock() - self.started if self.started is not None else 0.0
        return LoopRate(self.cycles, seconds, wire_limit_hz(self.stream.ids, self.bus.serial.baudrate))


@dataclass
class Trajectory:
    """A CSV trajectory: times (s), {id: [degrees...]}, and each row's line
    in its file, for the messages."""
    times: list
    angles: dict
    lines: list = None
    path: str = ""

    @property
    def period_ms(self) -> int:
        return round((self.times[-1] - self.times[0]) / (len(self.times) - 1) * 1000)

    def where(self, k: int) -> str:
        return f"{self.path} line {self.lines[k]}" if self.lines else f"row {k}"


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def read_trajectory(path: str) -> Trajectory:
    """A CSV: a header of "time" then one servo ID per column; a row per
    setpoint, evenly spaced. Every row is checked, and an error names its
    line: nothing is sent before the whole file has passed."""
    try:
        with open(path, newline="") as f:
            rows = [(n, r) for n, r in enumerate(csv.reader(f), 1)
                    if r and not r[0].lstrip().startswith("#")]
    except OSError as e:
        raise UsageError(f"cannot read {path}: {e.strerror}") from None
    except (csv.Error, UnicodeDecodeError) as e:
        raise UsageError(f"{path}: not a CSV file ({e}): nothing was sent") from None
    if len(rows) < 3:
        raise UsageError(f"{path}: a header and at least two rows are needed")
    line, header = rows[0]
    try:
        ids = [int(c) for c in header[1:]]
        _check_ids(ids)
    except (ValueError, UsageError) as e:
        raise UsageError(f"{path} line {line}: the header is 'time' and servo IDs ({e})") from None
    table, lines = [], []
    for line, r in rows[1:]:
        def bad(why):
            return UsageError(f"{path} line {line}: {why}; nothing was sent")
        if len(r) != len(ids) + 1:
            raise bad(f"every row has a time and one finite angle per servo ({len(ids)}), not {len(r)} values")
        try:
            values = [float(c) for c in r]
        except ValueError:
            cell = next(c for c in r if not _is_number(c))
            raise bad(f"{cell.strip()!r} is not a number: every row has a time (s) and one angle (deg) "
                      f"per servo") from None
        if not all(map(math.isfinite, values)):
            raise bad(f"every row has a time and one finite angle per servo, not {', '.join(r)}")
        for servo_id, degrees in zip(ids, values[1:]):
            try:
                check_range("angle", scaled(degrees, 10, "degrees"), -MAX_ANGLE_DECIDEG, MAX_ANGLE_DECIDEG, "deg", 10)
            except ValueOutOfRange as e:
                raise bad(f"servo {servo_id}'s {e}") from None
        table.append(values)
        lines.append(line)
    times = [r[0] for r in table]
    period = (times[-1] - times[0]) / (len(times) - 1)
    if period <= 0:
        raise UsageError(f"{path}: the times must be evenly spaced and rising; nothing was sent")
    for k in range(1, len(times)):
        if abs(times[k] - times[k - 1] - period) > 1e-4:
            raise UsageError(f"{path} line {lines[k]}: the times must be evenly spaced and rising "
                             f"({period * 1000:g} ms apart), not {times[k - 1]:g} then {times[k]:g} s; "
                             f"nothing was sent")
    try:
        check_range("period", round(period * 1000), *PERIOD_RANGE_MS, "ms")
    except ValueOutOfRange as e:
        raise ValueOutOfRange(f"{path}: the rows' {e}; nothing was sent") from None
    return Trajectory(times, {servo_id: [r[k + 1] for r in table] for k, servo_id in enumerate(ids)},
                      lines, path)


def check_period(limits: dict, period_ms: int, where: str = "") -> None:
    """A stream at period_ms against every servo's watchdog_ms (Limits.check_period):
    refused, UsageError, before anything is sent."""
    for servo_id, lim in limits.items():
        why = lim.check_period(servo_id, period_ms)
        if why:
            raise UsageError(f"{where}{why}; nothing was sent")


def check_trajectory(trajectory: Trajectory, limits: dict) -> None:
    """Every row against every servo's Limits, as Stream checks a send,
    before anything moves: a row outside them is refused with its line;
    the file's period against each servo's bus watchdog first."""
    period_ms = trajectory.period_ms
    check_period(limits, period_ms, f"{trajectory.path}: " if trajectory.path else "")
    for servo_id, rows in trajectory.angles.items():
        last = None
        for k, degrees in enumerate(rows):
            angle = scaled(degrees, 10, "degrees")
            why = limits[servo_id].check(servo_id, angle, last, period_ms)
            if why:
                raise ValueOutOfRange(f"{trajectory.where(k)}: {why}; nothing was sent")
            last = angle


@dataclass
class LeadIn:
    """How the servos reached a stream's first row."""
    start_deg: dict    # {id: where each was}
    target_deg: dict   # {id: the first row}
    end_deg: dict      # {id: where each arrived}
    took_s: float      # on the bus's clock
    soft_start_s: float  # the longest soft start that could have stretched it (items 49, 50)


def lead_in(bus: p.Bus, targets: dict, duration_s: float, configs: dict = None, poll_s: float = 0.01) -> LeadIn:
    """Moves every servo to targets ({id: degrees}, one multi-turn sync
    move of duration_s) and waits, on the bus's clock, until each has
    arrived: status bit 0 clear and within TOLERANCE_DEG. Every poll_s a
    Sync Monitor asks every servo's state, and feeds a bus watchdog (items
    64, 65) all the while. Soft start (49, 50) stretches the first move
    after power-up to its own time, and the wait allows for it: twice
    the planned time (a jerk limit's window included), plus the soft
    start, plus 2 s. A servo that did not arrive
    raises Refused saying where it is and why: nothing is streamed.
    configs: {id: user area} as read_configs read them, else read now."""
    from .group import sync_move
    from .servo import MotionSnapshot, Servo

    ids = list(targets)
    configs = configs or read_configs(bus, ids)
    soft = max(c["soft_start_time"] / 1000.0 if c["soft_start_on"] else 0.0 for c in configs.values())
    states = sync_monitor(bus, ids)
    missing = [i for i in ids if i not in states]
    if missing:
        raise NoReply(f"servo {missing[0]} did not answer a Sync Monitor: nothing was sent")
    start = {i: states[i].angle_decideg for i in ids}
    # A jerk limit (item 70) lengthens each servo's move by its window.
    planned = max(MoveRequest(interval_ms=to_ms(duration_s, "duration_s")).planned_s(
        scaled(targets[i], 10, "degrees") - start[i], jerk_limit(Servo(bus, i))) for i in ids)
    sync_move(bus, targets, duration_s, multi_turn=True)
    limit = 2.0 * planned + soft + 2.0
    begun = bus.clock()
    seen = dict.fromkeys(ids, 0)
    while True:
        bus.sleep(poll_s)
        states = sync_monitor(bus, ids)
        for servo_id, m in states.items():
            seen[servo_id] |= m.status
        if all(i in states and not states[i].status & EXECUTING for i in ids) or bus.clock() - begun >= limit:
            break
    took = bus.clock() - begun
    for servo_id in ids:
        if servo_id not in states:
            raise NoReply(f"servo {servo_id} did not answer at the end of the lead-in: nothing was streamed")
        m, target = states[servo_id], scaled(targets[servo_id], 10, "degrees")
        off = abs(m.angle_decideg - target) / 10
        if not m.status & EXECUTING and off <= TOLERANCE_DEG:
            continue
        if m.status & EXECUTING:
            why = f"did not arrive within {limit:.1f} s"
        elif seen[servo_id] & INHIBITING:
            why = "was stopped by a protection"
        elif seen[servo_id] & STALL:
            why = "was blocked: it stalled (status bit 2)"
        else:
            why = "stopped short"
        try:  # what held it back, where the servo can say (this firmware's ReadMotion)
            limiter = Servo(bus, servo_id).read_motion().limiter
            if limiter != MotionSnapshot.LIMITERS[0]:
                why += f" (held back by: {limiter})"
        except NoReply:
            pass
        raise Refused(f"servo {servo_id}: the lead-in to the first row ({target / 10:.1f} deg) {why}; "
                      f"at {m.angle_decideg / 10:.1f} deg, {off:.1f} deg from it, after {took:.2f} s. "
                      f"Nothing was streamed")
    return LeadIn({i: a / 10 for i, a in start.items()}, dict(targets),
                  {i: states[i].angle_decideg / 10 for i in ids}, took, soft)


@dataclass
class StreamReport:
    period_s: float
    cycles: int
    rms_deg: dict     # {id: RMS of the servo's angle against the trajectory}
    peak_deg: dict
    rate: LoopRate
    missed: int       # states that did not come back


def stream_file(bus: p.Bus, times, angles: dict, progress=None, limits: dict = None) -> StreamReport:
    """Streams the trajectory at its own period, the servos already at its
    first row (lead_in): each row is sent a period before its time
    (velocities by central differences, 0 at the first and last rows), and
    each servo's state from the cycle's Sync Monitor is compared with the
    trajectory at the moment it arrived. Every row is checked against the
    servos' limits (read from them if not given) before the first is sent."""
    ids = list(angles)
    period = times[1] - times[0]
    check_wire(ids, period, bus.serial.baudrate)
    loop = RobotLoop(bus, ids, period, limits, pace=False)  # paced here, against the rows' times
    check_trajectory(Trajectory(times, angles), loop.stream.limits)
    count = len(times)
    period_ms = loop.stream.period_ms
    # The rows as sent (0.1 deg): a velocity is theirs, so it is within
    # the speed the rows were checked against.
    sent = {i: [scaled(a, 10, "degrees") for a in angles[i]] for i in ids}

    def velocity(servo_id, k):
        # The servos start from rest and end at rest: no step of speed at
        # either end, which no motor follows (the cubic would back up to
        # reach the first row moving).
        if k in (0, count - 1):
            return 0.0
        a = sent[servo_id]
        return (a[k + 1] - a[k - 1]) * 100 / (2 * period_ms)

    def reference(servo_id, t):
        k = min(max((t - times[0]) / period, 0.0), count - 1.0)
        i = min(int(k), count - 2)
        a = angles[servo_id]
        return a[i] + (a[i + 1] - a[i]) * (k - i)

    errors = {i: [] for i in ids}
    # This firmware takes every servo's state as the Sync Monitor request
    # ends (servo.c: the answer waits for its turn ready): the nth answer
    # ends n answers' wire time after that. A USB adapter hands answers
    # over together, so the nth arrives at the earliest then: the earliest
    # such estimate is the instant, late by the adapter's wait alone.
    answer_s = p.answer_frame_size(p.MONITOR) * BITS_PER_BYTE / bus.serial.baudrate
    start = bus.clock() + period  # row 0 is for a period after it is sent
    for k in range(count):
        bus.sleep(max(0.0, start + (k - 1) * period - bus.clock()))
        states = loop.cycle({i: angles[i][k] for i in ids}, {i: velocity(i, k) for i in ids})
        if k > 0 and states:  # a state is compared with the trajectory when it was taken
            taken = min(loop.arrivals[i] - (n + 1) * answer_s for n, i in enumerate(ids) if i in states)
            for servo_id in ids:
                if servo_id not in states:
                    continue
                m = states[servo_id]
                at = times[0] + taken - start
                errors[servo_id].append(m.angle_decideg / 10 - reference(servo_id, at))
        if progress:
            progress(k + 1, count)
    rms = {i: math.sqrt(sum(e * e for e in v) / len(v)) if v else math.nan for i, v in errors.items()}
    peak = {i: max(map(abs, v)) if v else math.nan for i, v in errors.items()}
    return StreamReport(period, count, rms, peak, loop.rate(), loop.missed)


def cmd_stream(bus, args):
    """servoctl stream FILE.csv: the whole file is checked first, against
    each servo's limits and the wire's rate too; the servos move to the first row (a sync move
    of --lead-in seconds) and the command waits until they are there; then
    they follow the trajectory at its period. Prints the lead-in, each
    servo's tracking error and the cycle's rate."""
    import sys

    from .console import progress as Progress  # a closed pipe ends quietly (cli.main)

    trajectory = read_trajectory(args.file)
    angles = trajectory.angles
    configs = read_configs(bus, angles)
    limits = {i: Limits.of(cfg) for i, cfg in configs.items()}
    check_trajectory(trajectory, limits)
    check_wire(list(angles), trajectory.times[1] - trajectory.times[0], bus.serial.baudrate,
               f"{args.file}: ")  # before the lead-in: nothing moves
    lead = lead_in(bus, {i: a[0] for i, a in angles.items()}, args.lead_in, configs)
    with Progress(transient=True, disable=not sys.stderr.isatty()) as progress:
        task = progress.add_task("streaming", total=len(trajectory.times))
        report = stream_file(bus, trajectory.times, angles,
                             lambda done, total: progress.update(task, completed=done), limits)
    period = report.period_s
    stretched = ""
    if lead.soft_start_s and lead.took_s > args.lead_in + 0.1:
        stretched = (f" (soft start: the first move after power-up takes soft_start_time, "
                     f"{lead.soft_start_s * 1000:.0f} ms)")
    print(f"lead-in: at the first row after {lead.took_s:.2f} s{stretched}")
    for servo_id in angles:
        moved = lead.end_deg[servo_id] - lead.start_deg[servo_id]
        print(f"  servo {servo_id}: from {lead.start_deg[servo_id]:.1f} deg to {lead.end_deg[servo_id]:.1f} deg "
              f"({moved:+.1f} deg)")
        if abs(moved) >= 180.0:
            print(f"  warning: servo {servo_id} turned {abs(moved):.1f} deg to reach the first row: angles are "
                  f"from its zero, in the turn around it at power-up (docs/servoctl.md)")
    print(f"{report.cycles} setpoints at {1 / period:g} Hz to {len(angles)} servo(s)")
    for servo_id in angles:
        print(f"  servo {servo_id}: tracking error RMS {report.rms_deg[servo_id]:.2f} deg, "
              f"peak {report.peak_deg[servo_id]:.2f} deg")
    r = report.rate  # the wire could carry the file's rate (check_wire): a shortfall is the host's
    short = f" (warning: below the file's {1 / period:g} Hz: the host fell behind)" if r.rate_hz < 0.95 / period else ""
    print(f"  cycle (setpoints + Sync Monitor) ran at {r.rate_hz:.1f} Hz{short}; the wire allows "
          f"{r.wire_limit_hz:.0f} Hz at {bus.serial.baudrate} baud")
    if report.missed:
        print(f"  {report.missed} state(s) did not come back: those cycles are not counted")
    return 0
