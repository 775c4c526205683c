"""Streamed setpoints (StreamSetpoint, 0x45; docs/streaming.md): a host's
trajectory, one setpoint per servo per period, which each servo
interpolates at its 1 kHz tick. Stream sends them and RobotLoop runs a
robot's cycle (setpoints.py); a CSV trajectory is read and checked whole
(trajectory.py); here lead_in brings the servos to its first row and
stream_file runs it and reports how closely the servos followed it.

Every setpoint is checked against what its servo allows before it is sent
(Limits, read from the servo): its angle limits when they are on, and the
servo's top speed (750 deg/s) between one setpoint and the next. One out of
them is refused, never clamped: a clamped path is not the host's, and the
servo, without the next setpoint, brakes to a hold where the last one
was (docs/streaming.md). A file is checked whole before anything moves."""
import math
import struct
import time
from dataclasses import dataclass

from . import protocol as p
from .checks import scaled, to_ms
from .frame import jerk_limit
from .errors import NoReply, Refused
from .group import sync_monitor
from .loop_rate import BITS_PER_BYTE, LoopLate, LoopRate, check_wire, wire_limit_hz  # noqa: F401 (LoopLate: the API's)
from .move_request import MoveRequest
from .outcome import EXECUTING, INHIBITING, STALL, TOLERANCE_DEG
from .setpoints import Limits, RobotLoop, Stream, put_back_period, read_configs, tell_period  # noqa: F401 (Stream: the API's)
from .trajectory import Trajectory, check_trajectory, read_trajectory, row_velocity  # noqa: F401 (read_trajectory: the API's)


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
    # A simulator's clock against the PC's over the stream (None: a real
    # bus, or a paced simulator): below 1, a simulator slower than real
    # time held the cycles up.
    sim_speed: float = None
    paced: bool = False  # a paced simulator: the host's time cost none


def mean_period(times) -> float:
    """A file's period: its rows' mean step (read_trajectory has held each
    row to that grid), not its first step, which times written to the ms
    make up to 0.5 ms long or short."""
    return (times[-1] - times[0]) / (len(times) - 1)


def stream_file(bus: p.Bus, times, angles: dict, progress=None, limits: dict = None,
                host=None) -> StreamReport:
    """Streams the trajectory at its own period, the servos already at its
    first row (lead_in): each row is stamped with its time and sent the
    servo's depth (3/2 period) before it, where the servo plays it
    (velocities by central differences, 0 at the first and last rows);
    host (host_timing.HostTiming) moves each send as a real host's, and
    changes nothing where the servo plays it; and
    each servo's state from the cycle's Sync Monitor is compared with the
    trajectory at the moment it arrived. Every row is checked against the
    servos' limits (read from them if not given) before the first is sent."""
    ids = list(angles)
    period = mean_period(times)
    check_wire(ids, period, bus.serial.baudrate)
    loop = RobotLoop(bus, ids, period, limits, pace=False)  # paced here, against the rows' times
    check_trajectory(Trajectory(times, angles), loop.stream.limits)
    told = tell_period(bus, ids, loop.stream.period_ms)  # the servos' depth from the first row
    try:
        return _stream_rows(bus, times, angles, loop, progress, host)
    finally:
        put_back_period(bus, told)


def _stream_rows(bus, times, angles, loop, progress, host) -> StreamReport:
    ids = list(angles)
    period = mean_period(times)
    count = len(times)
    # The rows as sent (0.1 deg): a velocity is theirs, so it is within
    # the speed the rows were checked against.
    sent = {i: [scaled(a, 10, "degrees") for a in angles[i]] for i in ids}

    def velocity(servo_id, k):
        return row_velocity(times, sent[servo_id], k)  # as check_trajectory checked it

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
    # A punctual setpoint is played the servo's depth after its last byte
    # arrives: each row leaves that and its frame's time on the wire ahead.
    record = p.request_format(p.STREAM_SETPOINT)
    frame = p.request_frame(p.SYNC, bytes(3 + struct.calcsize(record) * len(ids))) if len(ids) > 1 else \
        p.request_frame(p.STREAM_SETPOINT, bytes(struct.calcsize(record)))
    # The servo's depth is 3/2 of the period it was told, in whole ms.
    depth = 1.5 * loop.stream.period_ms / 1000 + len(frame) * BITS_PER_BYTE / bus.serial.baudrate
    start = bus.clock() + depth
    wall_start = time.monotonic()
    for k in range(count):
        at = start + times[k] - times[0]  # each row stamped with its own time
        leaves = at - depth
        if host:
            leaves = host.leaves(k, leaves, period)
        bus.sleep(max(0.0, leaves - bus.clock()))
        states = loop.cycle({i: angles[i][k] for i in ids}, {i: velocity(i, k) for i in ids},
                            at_s=at)
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
    wall = time.monotonic() - wall_start
    paced = getattr(bus, "note_sent", None) is not None  # it runs only while the host waits
    speed = None if paced or bus.clock is time.monotonic or wall <= 0 else (bus.clock() - start + period) / wall
    return StreamReport(period, count, rms, peak, loop.rate(), loop.missed, speed, paced)
