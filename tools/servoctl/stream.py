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
import sys
import struct
import time
from dataclasses import dataclass

from . import protocol as p
from .checks import scaled, to_ms
from .frame import jerk_limit
from .errors import NoReply, Refused, UsageError
from .group import sync_monitor
from .loop_rate import BITS_PER_BYTE, LoopLate, LoopRate, check_wire, wire_limit_hz  # noqa: F401 (LoopLate: the API's)
from .move_request import MoveRequest
from .outcome import EXECUTING, INHIBITING, STALL, TOLERANCE_DEG
from .setpoints import Limits, RobotLoop, Stream, put_back_period, read_configs, tell_period  # noqa: F401 (Stream: the API's)
from .trajectory import Trajectory, check_trajectory, read_trajectory, row_velocity


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


def host_timing(args, bus=None):
    """The --host-jitter-ms / --host-late-every model, or None; on a bus
    whose clock is not a paced simulator's, said to add to the PC's own."""
    from .host_timing import HostTiming

    try:
        host = HostTiming(args.host_jitter_ms / 1000.0, args.host_late_every)
    except ValueError as e:
        raise UsageError(f"--host-jitter-ms, --host-late-every: {e}") from None
    if host and bus is not None and getattr(bus, "note_sent", None) is None:
        print("servoctl: the host-timing model's jitter adds to this PC's own timing here (a simulator in "
              "real time, or a servo); the model's figures alone are a paced simulator's (docs/streaming.md, "
              "\"Figures\")", file=sys.stderr)
    return host or None


def cmd_stream(bus, args):
    """servoctl stream FILE.csv: the whole file is checked first, against
    each servo's limits and the wire's rate too; the servos move to the first row (a sync move
    of --lead-in seconds) and the command waits until they are there; then
    they follow the trajectory at its period. Prints the lead-in, each
    servo's tracking error and the cycle's rate; exit 1 if a servo's error
    is beyond --tolerance or the cycles fell behind the file (_verdict)."""
    import sys

    from .console import progress as Progress  # a closed pipe ends quietly (cli.main)

    trajectory = read_trajectory(args.file)
    angles = trajectory.angles
    configs = read_configs(bus, angles)
    limits = {i: Limits.of(cfg) for i, cfg in configs.items()}
    check_trajectory(trajectory, limits)
    period = mean_period(trajectory.times)
    check_wire(list(angles), period, bus.serial.baudrate, f"{args.file}: ")  # before the lead-in: nothing moves
    cycle_s = 1 / wire_limit_hz(list(angles), bus.serial.baudrate)
    if cycle_s > FULL_CYCLE * period:
        print(f"servoctl: a cycle takes {cycle_s * 1000:.1f} ms of the {period * 1000:.1f} ms period at "
              f"{bus.serial.baudrate} baud: a frame the host sends late has little room (docs/streaming.md, "
              f"\"The cost of a full cycle\"); a higher baud rate or a longer period leaves it some", file=sys.stderr)
    lead = lead_in(bus, {i: a[0] for i, a in angles.items()}, args.lead_in, configs)
    with Progress(transient=True, disable=not sys.stderr.isatty()) as progress:
        task = progress.add_task("streaming", total=len(trajectory.times))
        report = stream_file(bus, trajectory.times, angles,
                             lambda done, total: progress.update(task, completed=done), limits,
                             host_timing(args, bus))
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
    print(f"{report.cycles} setpoints at {1 / period:.4g} Hz to {len(angles)} servo(s)")
    for servo_id in angles:
        print(f"  servo {servo_id}: tracking error RMS {report.rms_deg[servo_id]:.2f} deg, "
              f"peak {report.peak_deg[servo_id]:.2f} deg")
    r = report.rate  # check_wire let the file's rate through: _who_was_late says what held it up
    short = f" (below the file's {1 / period:.4g} Hz: {_who_was_late(report)})" if _late(report) else ""
    print(f"  cycle (setpoints + Sync Monitor) ran at {r.rate_hz:.1f} Hz{short}; the wire allows "
          f"{r.wire_limit_hz:.0f} Hz at {bus.serial.baudrate} baud")
    if report.missed:
        print(f"  {report.missed} state(s) did not come back: those cycles are not counted")
    return _verdict(report, args.tolerance, args.report_only)


# A cycle that fills more than this share of the period leaves a late
# frame little room: said before the stream (6 servos at 115 200 baud at
# 50 Hz, a cycle of 17.5 ms: docs/streaming.md).
FULL_CYCLE = 0.75

# A stream whose cycles ran below this share of the file's rate was sent
# late: its setpoints reached the servos after their times.
LATE_BELOW = 0.95


def _late(report) -> bool:
    return report.rate.rate_hz < LATE_BELOW / report.period_s


def _who_was_late(report) -> str:
    if report.paced:
        return (f"a cycle took {1000 / report.rate.rate_hz:.2f} ms of the paced simulator's time (the "
                f"host's own time costs it none): the wire, the servos' turnarounds and the USB adapter's "
                f"frames cannot carry the file's rate" if report.rate.rate_hz > 0 else "no cycle ran")
    if report.sim_speed is not None and report.sim_speed < LATE_BELOW:
        return (f"on a simulator that ran at {report.sim_speed:.2f}x real time "
                f"(this PC cannot run the file in real time on it: a lower rate, fewer servos, or servo_sim)")
    return "the host sent them late"


def _verdict(report, tolerance: float, report_only: bool) -> int:
    """0 if every servo followed the file within tolerance (RMS, degrees)
    and the setpoints went out at the file's rate; else 1, saying which
    (docs/streaming.md, "The verdict"). report_only: 0 whatever."""
    import sys

    off = {i: rms for i, rms in report.rms_deg.items() if not rms <= tolerance}  # NaN: no state came back
    why = [f"servo {i} followed the file {rms:.2f} deg RMS, beyond the tolerance of {tolerance:g} deg"
           for i, rms in off.items()]
    if _late(report):
        why.append(f"the setpoints went out at {report.rate.rate_hz:.1f} Hz against the file's "
                   f"{1 / report.period_s:g} Hz: {_who_was_late(report)}")
    if not why or report_only:
        return 0
    for reason in why:  # each on its own line, with its figure
        print(f"servoctl: error: {reason}", file=sys.stderr)
    return 1
