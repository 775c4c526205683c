"""servoctl stream FILE.csv: a trajectory file streamed to the servos
(servoctl.stream's lead_in and stream_file), its report, and the verdict
on it (docs/streaming.md, "The verdict")."""
import sys

from ..errors import UsageError
from ..loop_rate import check_wire, wire_limit_hz
from ..setpoints import Limits, read_configs
from ..stream import lead_in, mean_period, stream_file
from ..trajectory import check_trajectory, read_trajectory


def host_timing(args, bus=None):
    """The --host-jitter-ms / --host-late-every model, or None; on a bus
    whose clock is not a paced simulator's, said to add to the PC's own."""
    from ..host_timing import HostTiming

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
    from .console import progress as Progress  # a closed pipe ends quietly (cli.app.main)

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


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "stream": cmd_stream,
}
