"""servoctl record: a move sampled as the servo sees it, against its plan, as
CSV and a plot."""
import collections
import csv
import math
import os

from . import args as args_
from .. import extras, frame, outcome, registers
from ..errors import Refused, UsageError
from ..servo import Servo


def check_writable(path: str):
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise UsageError(f"cannot write {path}: {folder} is not a writable folder")


def cmd_record(bus, args):
    """Samples a move as the servo sees it (ReadMotion, 0x40: angle, setpoint,
    its own measured speed and tracking error, current and status, all of one
    instant); CSV and a PNG with the plan, the tracking error and the speeds."""
    check_writable(args.out + ".csv")
    extras.require("matplotlib")  # the plot, drawn after the move: refused before it instead
    s = Servo(bus, args.id)
    target = args_.decideg(args.angle)
    where = frame.check_target(s, target, args.multi_turn)
    start = s.monitor().angle_decideg
    request = args_.move_request(args)
    plan = request.plan(start, target, where.jerk)  # the S-curve where item 70 is set
    # Samples are stamped with the servo's own clock (ReadMotion's time), so
    # a host or simulator that falls behind does not bend the time axis.
    before = s.read_motion()
    s.send_move(target, request)
    samples = []
    done_at = None
    # A move the motor cannot follow arrives late; soft start (49/50) can
    # stretch the first one too.
    limit = 2.0 * len(plan) / 1000.0 + 10.0
    now = 0.0
    while now < limit:
        m = s.read_motion()  # one instant: angle, setpoint, speed, error, current, status
        now = m.seconds_since(before)
        samples.append((now, m))
        if done_at is None and now > 0.02 and not m.status & 1:
            done_at = now
        if done_at is not None and now > done_at + args.settle / 1000.0:
            break
    if done_at is None:
        raise Refused(f"servo {args.id} still moving after {limit:.1f} s (the samples are not written)")
    # Time 0 is when the servo's profile started, not when the host sent the
    # move: a host that was slow to send it does not shift the plan.
    began = _profile_start(samples, plan)
    samples = [(t - began, m) for t, m in samples]
    done_at -= began
    rows = []
    profile_end = None
    for t, m in samples:
        planned, planned_speed = _planned_at(plan, t)
        if profile_end is None and m.flags & m.PROFILE_ENDED:
            profile_end = round(t * 1000, 1)
        rows.append((round(t * 1000, 1), m.angle_decideg / 10.0, m.velocity_decideg_s / 10.0,
                     m.current_ma / 1000.0, round(planned, 2), m.setpoint_decideg / 10.0,
                     m.tracking_error_centideg / 100.0, round(planned_speed, 1), m.status,
                     m.flags, m.limiter, m.winding_decic / 10.0))
    csv_path = args.out + ".csv"
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time_ms", "angle_deg", "velocity_dps", "current_a", "planned_deg",
                    "setpoint_deg", "tracking_error_deg", "planned_velocity_dps", "status",
                    "motion_flags", "limiter", "winding_c"])
        w.writerows(rows)
    png_path = args.out + ".png"
    _plot(rows, plan, png_path, f"servo {args.id}: {start / 10:.1f} -> {target / 10:.1f} deg",
          profile_end, done_at * 1000)
    worst = max(abs(r[6]) for r in rows)
    ends = f"profile ended after {profile_end:.0f} ms, " if profile_end is not None else ""
    print(f"{len(rows)} samples over {rows[-1][0]:.0f} ms; {ends}finished after "
          f"{done_at * 1000:.0f} ms (planned {len(plan) - 1} ms); worst tracking error "
          f"{worst:.2f} deg; final {rows[-1][1]:.1f} deg")
    limited = collections.Counter(r[10] for r in rows if r[10] != "none")
    if limited:
        print("held back by " + ", ".join(f"{k} in {n} of {len(rows)} samples" for k, n in limited.most_common()))
    print(f"csv  {os.path.abspath(csv_path)}")
    print(f"plot {os.path.abspath(png_path)}")
    off = abs(rows[-1][1] - target / 10.0)
    if off > args.tolerance:
        seen = 0
        for _, m in samples:
            seen |= m.status
        why = (f"a protection ({', '.join(registers.status_names(seen & outcome.INHIBITING))})"
               if seen & outcome.INHIBITING else "a stall (status bit 2)" if seen & outcome.STALL
               else "nothing the servo reported")
        raise Refused(f"servo {args.id} did not arrive: {off:.1f} deg from {target / 10:.1f} deg "
                      f"(tolerance {args.tolerance} deg); stopped by {why}")
    print(f"arrived: {off:.2f} deg from {target / 10:.1f} deg")
    return 0


def _planned_at(plan, t_s: float) -> tuple:
    """(degrees, degrees per second) the plan gives at t_s: its start
    before the profile began (a sample taken before the servo's first tick
    of the move has t < 0), its end after."""
    ms = math.floor(t_s * 1000)
    if ms < 0:
        return plan[0] / 10.0, 0.0
    if ms >= len(plan) - 1:
        return plan[-1] / 10.0, 0.0
    return plan[ms] / 10.0, (plan[ms + 1] - plan[ms]) * 100.0


def _profile_start(samples, plan) -> float:
    """The servo time its profile started at: from the first sample whose
    setpoint has left the start, less the plan's time to that setpoint
    (the setpoint is the profile's own, so no host delay enters). 0 when
    no sample caught the setpoint between start and target."""
    start, end = plan[0], plan[-1]
    sign = 1 if end >= start else -1
    for t, m in samples:
        setpoint = m.setpoint_decideg
        if sign * (setpoint - start) > 0 and sign * (end - setpoint) > 0:
            k = next(i for i, p in enumerate(plan) if sign * (p - setpoint) >= 0)
            return t - k / 1000.0
    return 0.0


def _plot(rows, plan, path, title, profile_end, finished):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = [r[0] for r in rows]
    fig, (ax1, ax2, ax3) = plt.subplots(3, 1, sharex=True, figsize=(8, 8),
                                        gridspec_kw={"height_ratios": [3, 2, 2]})
    ax1.plot(range(len(plan)), [p / 10.0 for p in plan], label="planned", color="0.7", lw=3)
    ax1.plot(t, [r[5] for r in rows], label="setpoint (servo)", color="tab:green", lw=1)
    ax1.plot(t, [r[1] for r in rows], ".-", label="measured", ms=3)
    ax1.set_ylabel("angle (deg)")
    ax1.set_title(title)
    ax2.plot(t, [r[6] for r in rows], color="tab:purple")
    ax2.axhline(0, color="0.8", lw=0.8)
    ax2.set_ylabel("tracking error\nsetpoint - measured (deg)")
    ax3.plot(range(len(plan) - 1), [(plan[k + 1] - plan[k]) * 100.0 for k in range(len(plan) - 1)],
             label="planned", color="0.7", lw=3)
    ax3.plot(t, [r[2] for r in rows], label="measured by the servo")
    ax3.set_ylabel("speed (deg/s)")
    ax3.set_xlabel("time (ms)")
    amps = ax3.twinx()
    amps.plot(t, [r[3] for r in rows], color="tab:red", lw=0.8)
    amps.set_ylabel("current (A)", color="tab:red")
    for ax in (ax1, ax2, ax3):
        if profile_end is not None:
            ax.axvline(profile_end, color="tab:green", ls="--", lw=0.8)
        ax.axvline(finished, color="tab:orange", ls=":", lw=1)
    ax1.plot([], [], color="tab:green", ls="--", lw=0.8, label="profile ends")
    ax1.plot([], [], color="tab:orange", ls=":", lw=1, label="finished (status bit 0)")
    ax1.legend(fontsize=8)
    ax3.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "record": cmd_record,
}
# The optional modules a command needs, checked before its port opens
# (app.py): a missing plot library named, not a port's error first.
EXTRAS = {
    "record": ("matplotlib",),
}
