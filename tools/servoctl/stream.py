"""Streamed setpoints (StreamSetpoint, 0x45; docs/streaming.md): a host's
trajectory, one setpoint per servo per period, which each servo
interpolates at its 1 kHz tick. Stream sends them; RobotLoop is a robot's
whole cycle (one SyncCommand of setpoints, one Sync Monitor) with its rate
against the wire's; stream_file runs a CSV trajectory and reports how
closely the servos followed it."""
import csv
import math
import struct
from dataclasses import dataclass

from . import protocol as p
from .checks import check_range, scaled
from .errors import UsageError
from .group import MAX_SYNC_RECORDS, monitor_answers, monitor_request

MAX_ANGLE_DECIDEG = 3686400    # the multi-turn range (ReadMultiTurnAngle)
MAX_SPEED_DECIDEG_S = 7500     # the firmware clamps beyond (schema.toml)
PERIOD_RANGE_MS = (1, 1000)    # item 69's
BITS_PER_BYTE = 10             # 8N1


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


class Stream:
    """Setpoints for ids every period_s: send({id: degrees}) once a period,
    one period ahead of where the servos should be (each servo reaches a
    setpoint a period after it arrives). Velocities, in degrees per second,
    are given or taken from the last two setpoints. One servo gets its own
    packet; several, one SyncCommand frame, so they start together."""

    def __init__(self, bus: p.Bus, ids, period_s: float):
        self.bus = bus
        self.ids = _check_ids(ids)
        self.period_ms = check_range("period", scaled(period_s, 1000, "period_s"), *PERIOD_RANGE_MS, "ms")
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
            if velocities is not None:
                speed = scaled(velocities[servo_id], 10, "velocity")
            elif servo_id in self._last:
                speed = round((angle - self._last[servo_id]) * 1000 / self.period_ms)
            else:
                speed = 0
            speed = max(-MAX_SPEED_DECIDEG_S, min(MAX_SPEED_DECIDEG_S, speed))
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


def wire_bytes(code: int, content: bytes) -> int:
    return len(p.request_frame(code, content))


@dataclass
class LoopRate:
    cycles: int
    seconds: float           # on the bus's clock
    wire_limit_hz: float     # the cycle's bytes back to back at the baud rate

    @property
    def rate_hz(self) -> float:
        return self.cycles / self.seconds if self.seconds > 0 else 0.0

    @property
    def ratio(self) -> float:
        return self.rate_hz / self.wire_limit_hz


class RobotLoop:
    """A robot's cycle as fast as the bus goes: setpoints to every servo
    (one SyncCommand of StreamSetpoint) and every servo's state back (one
    Sync Monitor). cycle() returns {id: Monitor}; rate() compares the
    cycles run with the wire's limit, every byte of both frames and of the
    answers back to back."""

    def __init__(self, bus: p.Bus, ids, period_s: float):
        self.stream = Stream(bus, ids, period_s)
        self.bus = bus
        self.cycles = 0
        self.started = None
        self.missed = 0
        self.arrivals = {}  # {id: the bus clock when its last state arrived}
        self._monitor = monitor_request(self.stream.ids)

    def cycle_bytes(self) -> int:
        ids = self.stream.ids
        setpoints = p.SYNC, bytes([p.STREAM_SETPOINT, 9, len(ids)]) + bytes(9 * len(ids))
        monitor = p.SYNC, bytes([p.MONITOR, 1, len(ids)] + ids)
        if len(ids) == 1:
            setpoints = p.STREAM_SETPOINT, bytes(9)
        return wire_bytes(*setpoints) + wire_bytes(*monitor) + len(ids) * p.answer_frame_size(p.MONITOR)

    def cycle(self, targets: dict, velocities: dict = None) -> dict:
        if self.started is None:
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
        limit = self.bus.serial.baudrate / BITS_PER_BYTE / self.cycle_bytes()
        return LoopRate(self.cycles, seconds, limit)


def read_trajectory(path: str):
    """(times_s, {id: [degrees...]}) from a CSV: a header of "time" then
    one servo ID per column; a row per setpoint, evenly spaced."""
    try:
        with open(path, newline="") as f:
            rows = [r for r in csv.reader(f) if r and not r[0].lstrip().startswith("#")]
    except OSError as e:
        raise UsageError(f"cannot read {path}: {e.strerror}") from None
    if len(rows) < 3:
        raise UsageError(f"{path}: a header and at least two rows are needed")
    try:
        ids = [int(c) for c in rows[0][1:]]
        table = [[float(c) for c in r] for r in rows[1:]]
    except ValueError as e:
        raise UsageError(f"{path}: the header is 'time' and servo IDs, every row numbers ({e})") from None
    _check_ids(ids)
    if any(len(r) != len(ids) + 1 or not all(map(math.isfinite, r)) for r in table):
        raise UsageError(f"{path}: every row has a time and one finite angle per servo ({len(ids)})")
    times = [r[0] for r in table]
    period = (times[-1] - times[0]) / (len(times) - 1)
    if period <= 0 or any(abs(b - a - period) > 1e-4 for a, b in zip(times, times[1:])):
        raise UsageError(f"{path}: the times must be evenly spaced and rising")
    return times, {servo_id: [r[k + 1] for r in table] for k, servo_id in enumerate(ids)}


@dataclass
class StreamReport:
    period_s: float
    cycles: int
    rms_deg: dict     # {id: RMS of the servo's angle against the trajectory}
    peak_deg: dict
    rate: LoopRate
    missed: int       # states that did not come back


def stream_file(bus: p.Bus, times, angles: dict, progress=None) -> StreamReport:
    """Streams the trajectory at its own period, the servos already at its
    first row: each row is sent a period before its time (velocities by
    central differences, 0 at the first and last rows), and each servo's state from the cycle's Sync
    Monitor is compared with the trajectory at the moment it arrived."""
    ids = list(angles)
    period = times[1] - times[0]
    loop = RobotLoop(bus, ids, period)
    count = len(times)

    def velocity(servo_id, k):
        # The servos start from rest and end at rest: no step of speed at
        # either end, which no motor follows (the cubic would back up to
        # reach the first row moving).
        if k in (0, count - 1):
            return 0.0
        a = angles[servo_id]
        return (a[k + 1] - a[k - 1]) / (2 * period)

    def reference(servo_id, t):
        k = min(max((t - times[0]) / period, 0.0), count - 1.0)
        i = min(int(k), count - 2)
        a = angles[servo_id]
        return a[i] + (a[i + 1] - a[i]) * (k - i)

    errors = {i: [] for i in ids}
    # This firmware takes every servo's state as the Sync Monitor request
    # ends (servo.c: the answer waits for its turn ready): the nth answer
    # arrives n answers' wire time after that.
    answer_s = p.answer_frame_size(p.MONITOR) * BITS_PER_BYTE / bus.serial.baudrate
    start = bus.clock() + period  # row 0 is for a period after it is sent
    for k in range(count):
        bus.sleep(max(0.0, start + (k - 1) * period - bus.clock()))
        states = loop.cycle({i: angles[i][k] for i in ids}, {i: velocity(i, k) for i in ids})
        if k > 0:  # a state is compared with the trajectory when it was taken
            for n, servo_id in enumerate(ids):
                if servo_id not in states:
                    continue
                m = states[servo_id]
                at = times[0] + loop.arrivals[servo_id] - (n + 1) * answer_s - start
                errors[servo_id].append(m.angle_decideg / 10 - reference(servo_id, at))
        if progress:
            progress(k + 1, count)
    rms = {i: math.sqrt(sum(e * e for e in v) / len(v)) if v else math.nan for i, v in errors.items()}
    peak = {i: max(map(abs, v)) if v else math.nan for i, v in errors.items()}
    return StreamReport(period, count, rms, peak, loop.rate(), loop.missed)


def cmd_stream(bus, args):
    """servoctl stream FILE.csv: the servos move to the first row (a sync
    move of --lead-in seconds), then follow the trajectory at its period;
    prints each servo's tracking error and the cycle's rate."""
    import sys

    from rich.progress import Progress

    from .group import sync_move

    times, angles = read_trajectory(args.file)
    period = times[1] - times[0]
    check_range("period", scaled(period, 1000, "period"), *PERIOD_RANGE_MS, "ms")
    sync_move(bus, {i: a[0] for i, a in angles.items()}, args.lead_in, multi_turn=True)
    bus.sleep(args.lead_in + 0.2)
    with Progress(transient=True, disable=not sys.stderr.isatty()) as progress:
        task = progress.add_task("streaming", total=len(times))
        report = stream_file(bus, times, angles,
                             lambda done, total: progress.update(task, completed=done))
    print(f"{report.cycles} setpoints at {1 / period:g} Hz to {len(angles)} servo(s)")
    for servo_id in angles:
        print(f"  servo {servo_id}: tracking error RMS {report.rms_deg[servo_id]:.2f} deg, "
              f"peak {report.peak_deg[servo_id]:.2f} deg")
    r = report.rate
    print(f"  cycle (setpoints + Sync Monitor) ran at {r.rate_hz:.1f} Hz; the wire allows "
          f"{r.wire_limit_hz:.0f} Hz at {bus.serial.baudrate} baud")
    if report.missed:
        print(f"  {report.missed} state(s) did not come back: those cycles are not counted")
    return 0
