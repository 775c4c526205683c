"""servoctl: talk to a UART bus servo on a serial port or the simulator.

Angles are given in degrees and speeds in degrees per second; the tool turns
them into the protocol's 0.1 degree units and checks every value before
anything is sent.

Exit codes: 0 done; 1 the servo refused, or a move did not arrive (the
message says why); 2 a usage error (nothing was sent); 3 no reply; 4 the
serial link failed; 130 interrupted (Ctrl-C)."""
import argparse
import csv
import json
import math
import os
import sys
import time

from . import __version__, config_diff, config_file, frame, group, ids, ntc, outcome, registers, scan, units
from . import protocol as p
from .profile import positions, velocity_timing
from .protocol import BadAnswer, Bus, NoReply, Refused, ServoError, UsageError
from .servo import Servo, check_profile

EXIT_INTERRUPTED = 130


def _baud(text: str) -> int:
    """--baud: a rate the servos speak (data item 36)."""
    rates = registers.BAUD_RATES.values()
    if text.isdigit() and int(text) in rates:
        return int(text)
    raise argparse.ArgumentTypeError(f"a servo speaks {', '.join(map(str, rates))} bits/s, not {text}")


def _reply_timeout(text: str) -> float:
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not 0.001 <= seconds <= 10:
        raise argparse.ArgumentTypeError(f"a reply timeout is 0.001..10 s, not {text}")
    return seconds


def decideg(degrees: float) -> int:
    return int(round(degrees * 10))


def id_number(text: str) -> int:
    """argparse type: a servo ID, 0..254."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a servo ID: {text!r}") from None
    if not 0 <= value <= p.MAX_ID:
        raise argparse.ArgumentTypeError(f"servo IDs are 0..{p.MAX_ID}, not {value}")
    return value


def finite(text: str) -> float:
    """argparse type: a real number of degrees (no nan, no inf)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


def fmt_status(status: int) -> str:
    names = registers.status_names(status)
    return ", ".join(names) if names else "ok"


def live_celsius(adc: int):
    try:
        return round(ntc.adc_to_celsius(adc), 2)
    except ValueError:
        return None


def describe_temperature(adc: int) -> str:
    try:
        return f"{ntc.adc_to_celsius(adc):.1f} degC (ADC {adc})"
    except ValueError:
        return f"ADC {adc} (no sensor?)"


# ---- commands --------------------------------------------------------------

def cmd_scan(bus, args):
    from rich.progress import Progress

    rates = [bus.serial.baudrate]  # the one asked for first
    if args.all_bauds and bus.port.startswith("socket://"):
        print("servoctl: socket:// carries no baud rate (the far end sets it): scanning once",
              file=sys.stderr)
    elif args.all_bauds:
        rates += [r for r in sorted(registers.BAUD_RATES.values()) if r != rates[0]]
    found = []
    interrupted = False
    with Progress(transient=True, disable=not sys.stderr.isatty()) as progress:
        task = progress.add_task("scanning", total=len(rates) * (args.last - args.first + 1))
        try:
            for rate in rates:
                bus.serial.baudrate = rate
                window = args.reply_timeout or scan.reply_window_s(rate)
                for servo_id in range(args.first, args.last + 1):
                    if (f := scan.probe(bus, servo_id, window)) is not None:
                        found.append(f)
                        if not args.json:
                            progress.console.print(f.describe(), soft_wrap=True, markup=False,
                                                   highlight=False)
                    progress.advance(task)
        except KeyboardInterrupt:
            interrupted = True
    if args.json:
        print(json.dumps([f.as_json() for f in found]))
    else:
        print(f"{len(found)} servo(s) found" if found else "no servo answered",
              "(interrupted)" if interrupted else "")
    if interrupted:
        print("servoctl: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    if any(f.shared for f in found):
        print(f"servoctl: error: IDs held by two or more servos: "
              f"{', '.join(str(f.id) for f in found if f.shared)}", file=sys.stderr)
        return Refused.exit_code
    return 0 if found else 3


def cmd_ping(bus, args):
    if args.json:
        answered = Servo(bus, args.id).ping()
        print(json.dumps({"id": args.id, "answered": answered}))
        return 0 if answered else 3
    if Servo(bus, args.id).ping():
        print(f"servo {args.id}: answered")
        return 0
    print(f"servo {args.id}: no reply")
    return NoReply.exit_code


def cmd_info(bus, args):
    s = Servo(bus, args.id)
    m = s.monitor()
    if args.json:
        print(json.dumps({
            "id": args.id, "voltage_v": m.voltage_mv / 1000, "current_a": m.current_ma / 1000,
            "power_w": m.power_mw / 1000, "temperature_adc": m.temperature_adc,
            "temperature_c": live_celsius(m.temperature_adc), "status": registers.status_names(m.status),
            "angle_deg": m.angle_decideg / 10, "turns": m.turns, "model": s.read("model"),
            "firmware": s.read("firmware"), "serial": s.read("serial")}))
        return 0
    print(f"servo {args.id}")
    print(f"  voltage      {m.voltage_mv / 1000:.2f} V")
    print(f"  current      {m.current_ma / 1000:.3f} A")
    print(f"  power        {m.power_mw / 1000:.2f} W")
    print(f"  temperature  {describe_temperature(m.temperature_adc)}")
    print(f"  status       0x{m.status:02x}: {fmt_status(m.status)}")
    print(f"  angle        {m.angle_decideg / 10:.1f} deg ({m.turns} turns)")
    print(f"  model        0x{s.read('model'):04x}")
    print(f"  firmware     0x{s.read('firmware'):04x}")
    print(f"  serial       0x{s.read('serial'):08x}")
    return 0


def cmd_id(bus, args):
    if args.action == "assign":
        if len(args.rest) != 2:
            raise UsageError("id assign takes SERIAL ID (scan shows serial numbers)")
        serial, new_id = ids.serial_number(args.rest[0]), id_number(args.rest[1])
        ids.assign(bus, serial, new_id)
        print(f"servo serial 0x{serial:08x} is now ID {new_id}")
        return 0
    if args.rest:
        raise UsageError("id bringup takes no arguments: --from-id, --first, --count, --wait-s")
    done = ids.bring_up(bus, args.from_id, args.first, args.count, args.wait_s,
                        lambda line: print(line, flush=True))
    print(f"{len(done)} servo(s) numbered: " + ", ".join(f"0x{s:08x} -> {i}" for s, i in done))
    return 0


def cmd_bench(bus, args):
    from . import bench, image as img

    figures = [bench.sync_monitor_rounds(bus, args.ids, args.seconds)]
    if args.update_id is not None:
        image = (img.load(args.image) if args.image else
                 bench.image_of_size(args.image_size, 0x0010, img.BOARDS["host_sim"]))
        figures.append(bench.update_time(bus, args.update_id, image))
    for f in figures:
        print(json.dumps({"what": f.what, "measured": f.measured, "limit": f.limit, "unit": f.unit,
                          "ratio": f.ratio}) if args.json else f.line())
    return 0


def cmd_store(bus, args):
    """ReadStore: the config store's health, and what flash work cost the
    bus (answers dropped, bytes lost): a host that missed an answer, or
    whose broadcast a servo may have missed, learns it here."""
    h = Servo(bus, args.id).read_store()
    if args.json:
        print(json.dumps({"id": h.id, "flags": h.flag_names(), "records": h.records,
                          "page_erases": h.page_erases, "rated_cycles": h.rated_cycles,
                          "budget": h.budget, "op_seconds": h.op_seconds, "failures": h.failures,
                          "answers_dropped": h.answers_dropped, "bytes_lost": h.bytes_lost}))
        return 0
    print(f"servo {args.id}: config store")
    print(f"  state            {', '.join(h.flag_names()) or 'saved'}")
    print(f"  records          {h.records} (wear budget {h.budget} by now)")
    print(f"  page erases      {h.page_erases} of {h.rated_cycles} rated")
    print(f"  operating time   {h.op_seconds} s")
    print(f"  failed saves     {h.failures}")
    print(f"  answers dropped  {h.answers_dropped} (requests that arrived during a flash erase: "
          f"carried out, not answered)")
    print(f"  bytes lost       {h.bytes_lost}")
    return 0


def _shown(item, raw: int, as_raw: bool) -> str:
    if as_raw:
        return f"{raw}{' ' + item.unit if item.unit else ''}"
    return units.show(item, raw)


def _print_config(values: dict, as_raw: bool):
    for item in registers.USER:
        print(f"  {item.id:2d} {item.name:<18} {_shown(item, values[item.name], as_raw)}")


def cmd_config_diff(bus, args):
    pairs = config_diff.pair(config_diff.resolve(bus, args.target), config_diff.resolve(bus, args.other))
    if not pairs:
        raise UsageError("nothing to compare: no entry of one side has a serial number or ID of the other")
    found = []
    for a, b in pairs:
        differ = config_diff.differences(a, b)
        found.append(differ)
        if args.json:
            print(json.dumps({"a": a.label, "b": b.label, "differ": {
                k: [config_diff.shown(k, x), config_diff.shown(k, y)] for k, (x, y) in differ.items()}}))
            continue
        print(f"{a.label} | {b.label}: " + (f"{len(differ)} item(s) differ" if differ else "the same"))
        for name, (x, y) in differ.items():
            print(f"  {name:<18} {config_diff.shown(name, x):>14} | {config_diff.shown(name, y)}")
    return 1 if any(found) else 0


def cmd_config(bus, args):
    if args.action == "diff":
        return cmd_config_diff(bus, args)
    s = Servo(bus, args.id)
    if args.action == "get":
        item = registers.find(args.name)
        raw = s.read(item.id)
        if args.json:
            print(json.dumps({"id": item.id, "name": item.name, "raw": raw, "value": units.show(item, raw)}))
        else:
            print(f"{item.name} = {_shown(item, raw, args.raw)}")
    elif args.action == "set":
        item = registers.find(args.name)
        if args.raw:
            try:
                value = int(args.value, 0)
            except ValueError:
                raise UsageError(f"{item.name} takes a whole number in protocol units, "
                                 f"not {args.value!r}") from None
        else:
            value = units.to_raw(item, args.value)
        if item.name == "servo_id":
            group.id_is_free(bus, args.id, value)
        s.write(item.id, value)
        print(f"{item.name} = {_shown(item, value, args.raw)}")
    elif args.action == "dump":
        values = s.read_all()
        if args.json:
            print(json.dumps(values if args.raw else config_file.config_json(values, config_file.servo_of(s))))
        else:
            _print_config(values, args.raw)
    elif args.action == "save":
        config_file.write(args.file, config_file.config_json(s.read_all(), config_file.servo_of(s)))
        print(f"saved the user area of servo {args.id} to {args.file}")
    elif args.action == "load":
        entry = config_file.parse_config(config_file.read(args.file), args.file, args.raw)
        kept = group.write_user_area(s, entry.values, args.with_link)  # validated before sending
        notes = [f"kept {', '.join(f'{k} {s.read(k)}' for k in kept)}; --with-link to change"] if kept else []
        if entry.raw:
            notes.append("a raw file: protocol units")
        if entry.serial is not None and entry.serial != s.read("serial"):
            notes.append(f"the file is servo serial 0x{entry.serial:08x}'s")
        note = f" ({'; '.join(notes)})" if notes else ""
        print(f"loaded {len(entry.values)} item(s) from {args.file} into servo {args.id}{note}")
    elif args.action == "reset":
        s.reset_user_data()
        print(f"servo {args.id}: user area reset (ID and baud rate kept)")
    return 0


def _move_args(args):
    """Packet choice: --velocity: 12/15; --interval with --acc or --dec:
    11/14; --interval alone: the plain angle modes 8/13."""
    acc = 20 if args.acc is None else args.acc
    dec = 20 if args.dec is None else args.dec
    kw = dict(acc_ms=acc, dec_ms=dec, power_mw=args.power, multi_turn=args.multi_turn)
    if args.velocity is not None:
        kw["velocity"] = decideg(args.velocity)
    else:
        kw["interval_ms"] = args.interval if args.interval is not None else 1000
        kw["ramps"] = args.acc is not None or args.dec is not None
    check_profile(acc, dec, kw.get("interval_ms"), kw.get("velocity"))
    return kw


def cmd_move(bus, args):
    s = Servo(bus, args.id)
    kw = _move_args(args)
    asked = decideg(args.angle)
    where = frame.check_target(s, asked, args.multi_turn)
    plan = outcome.plan_move(s, asked, kw, where) if args.wait else None
    s.move(asked, **kw)
    outcome.taken(s, "the move")
    if not args.wait:
        return 0
    result = outcome.wait_for_arrival(s, plan, args.tolerance, args.timeout_s)
    if not result.arrived:
        raise Refused(f"servo {args.id}: {result.reason}")
    print(f"servo {args.id}: at {result.angle / 10:.1f} deg after {result.took_s * 1000:.0f} ms "
          f"({outcome.planned_text(plan, result.took_s)})")
    return 0


def cmd_wheel(bus, args):
    s = Servo(bus, args.id)
    s.wheel(args.action, args.speed, args.value, args.cw)
    outcome.taken(s, f"wheel {args.action}")
    return 0


def cmd_damping(bus, args):
    s = Servo(bus, args.id)
    s.damping(args.power)
    outcome.taken(s, "damping")
    return 0


def cmd_stop(bus, args):
    s = Servo(bus, args.id)
    s.stop(args.mode, args.power)
    outcome.taken(s, f"stop ({args.mode})")
    return 0


def cmd_origin(bus, args):
    s = Servo(bus, args.id)
    if args.reset_turns:
        s.reset_multi_turn()
    else:
        s.set_origin()
    bus.sleep(0.01)
    try:
        outcome.taken(s, "a new origin")
    except Refused:
        raise Refused(f"servo {args.id} refused a new origin: release it first with "
                      f"'servoctl stop {args.id}'") from None
    angle, turns = s.multi_turn_angle()
    print(f"servo {args.id}: now {angle / 10:.1f} deg, {turns} turns")
    return 0


def _target(text: str):
    """ID:DEGREES, for sync-move."""
    servo_id, sep, degrees = text.partition(":")
    try:
        if not sep:
            raise ValueError
        return int(servo_id), finite(degrees)
    except (ValueError, argparse.ArgumentTypeError):
        raise argparse.ArgumentTypeError(f"not ID:DEGREES: {text!r}") from None


def cmd_sync_move(bus, args):
    ids = [servo_id for servo_id, _ in args.targets]
    twice = sorted({i for i in ids if ids.count(i) > 1})
    if twice:
        raise UsageError(f"servo {', '.join(map(str, twice))} is given more than one target")
    targets = dict(args.targets)
    group.sync_move(bus, targets, args.interval / 1000.0, args.power / 1000.0, args.multi_turn)
    for servo_id in targets:
        outcome.taken(Servo(bus, servo_id), "the sync move")
    print(f"{len(targets)} servo(s) moving together")
    return 0


def cmd_broadcast_move(bus, args):
    ids = _ids_on_bus(bus, args.ids)
    group.broadcast_move(bus, args.angle, args.interval / 1000.0, args.power / 1000.0, ids)
    print(f"{len(ids)} servo(s) moving to {args.angle:.1f} deg")
    return 0


def cmd_async(bus, args):
    if args.action == "begin":
        group.begin_async(bus)
    else:
        group.end_async(bus, cancel=args.action == "cancel")
    return 0


def _ids_on_bus(bus, ids):
    if ids:
        return ids
    timeout = scan.reply_window_s(bus.serial.baudrate)
    return [i for i in range(p.MAX_ID + 1) if Servo(bus, i).ping(timeout=timeout)]


def cmd_backup(bus, args):
    ids = _ids_on_bus(bus, args.ids)
    if not ids:
        raise NoReply("no servo answered: nothing to back up")
    group.backup(bus, ids, args.file)
    print(f"saved {len(ids)} servo(s) ({', '.join(map(str, ids))}) to {args.file}")
    return 0


def cmd_restore(bus, args):
    done = group.restore(bus, args.file, args.with_link)
    print(f"restored {len(done)} servo(s) ({', '.join(map(str, done))}) from {args.file}")
    return 0


def cmd_monitor(bus, args):
    from .live import has_display, monitor

    if args.plot_file:
        _writable(args.plot_file)
    plot = args.plot
    if plot and not has_display():
        print("servoctl: warning: --plot: no display (DISPLAY and WAYLAND_DISPLAY are unset), so no "
              "window; sampling without it. --plot-file FILE saves the plot instead", file=sys.stderr)
        plot = False
    never = {}
    try:
        never = monitor(bus, args.ids, args.every, args.count, args.sync, args.json, plot, args.plot_file)
    except KeyboardInterrupt:
        pass  # the way to stop a monitor
    if args.plot_file:
        print(f"plot {os.path.abspath(args.plot_file)}", file=sys.stderr if args.json else sys.stdout)
    if never:
        raise NoReply("; ".join(why or f"servo {i} never answered" for i, why in sorted(never.items())))
    return 0


def _writable(path: str):
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise UsageError(f"cannot write {path}: {folder} is not a writable folder")


def cmd_record(bus, args):
    """Samples a move as the servo sees it (ReadMotion, 0x40: angle, setpoint,
    its own measured speed and tracking error, current and status, all of one
    instant); CSV and a PNG with the plan, the tracking error and the speeds."""
    _writable(args.out + ".csv")
    s = Servo(bus, args.id)
    target = decideg(args.angle)
    frame.check_target(s, target, args.multi_turn)
    start = s.monitor().angle_decideg
    kw = _move_args(args)
    acc = max(kw["acc_ms"], 20)
    dec = max(kw["dec_ms"], 20)
    if "velocity" in kw:
        n1, nc, n3 = velocity_timing(target - start, 0.0, kw["velocity"] / 1000.0, acc, dec)
    else:
        interval = max(kw["interval_ms"], acc + dec)
        n1, nc, n3 = acc, interval - acc - dec, dec
    plan = positions(start, target, n1, nc, n3)
    # Samples are stamped with the servo's own clock (ReadMotion's time), so
    # a host or simulator that falls behind does not bend the time axis.
    before = s.read_motion()
    s.move(target, **kw)
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
                     m.flags))
    csv_path = args.out + ".csv"
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time_ms", "angle_deg", "velocity_dps", "current_a", "planned_deg",
                    "setpoint_deg", "tracking_error_deg", "planned_velocity_dps", "status",
                    "motion_flags"])
        w.writerows(rows)
    png_path = args.out + ".png"
    _plot(rows, plan, png_path, f"servo {args.id}: {start / 10:.1f} -> {target / 10:.1f} deg",
          profile_end, done_at * 1000)
    worst = max(abs(r[6]) for r in rows)
    ends = f"profile ended after {profile_end:.0f} ms, " if profile_end is not None else ""
    print(f"{len(rows)} samples over {rows[-1][0]:.0f} ms; {ends}finished after "
          f"{done_at * 1000:.0f} ms (planned {len(plan) - 1} ms); worst tracking error "
          f"{worst:.2f} deg; final {rows[-1][1]:.1f} deg")
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


def _interrupt(signum, frame):
    raise KeyboardInterrupt


def _version(v) -> str:
    return "none" if v is None else f"0x{v:04x}"


def cmd_update(bus, args):
    from rich.progress import BarColumn, DownloadColumn, Progress, TextColumn, TimeRemainingColumn

    from . import image as img
    from . import update as upd

    # `update IMAGE ID...` or `update ID... IMAGE`: the image is the one
    # that is not a number.
    ids, images = [], []
    for arg in args.targets:
        (ids if arg.isdigit() else images).append(arg)
    if len(images) != 1 or not ids:
        raise UsageError("update takes one image and one or more servo IDs")
    for servo_id in ids:
        if not 0 <= int(servo_id) <= p.MAX_ID:
            raise UsageError(f"servo ID {servo_id} is not 0-{p.MAX_ID}")
    image = img.load(images[0])
    failed = []
    for servo_id in map(int, ids):
        if args.catch:
            print(f"servo {servo_id}: power it up now (waiting {args.catch:g} s for its bootloader)",
                  file=sys.stderr)
            upd.catch(bus, servo_id, args.catch)
        started = time.monotonic()
        columns = [TextColumn(f"servo {servo_id}"), BarColumn(), DownloadColumn(), TimeRemainingColumn()]
        try:
            with Progress(*columns, transient=True, disable=not sys.stderr.isatty()) as progress:
                task = progress.add_task("update", total=len(image.data))
                before, after = upd.update(bus, servo_id, image,
                                           lambda done, total: progress.update(task, completed=done,
                                                                               total=total))
        except ServoError as e:
            print(f"servo {servo_id}: failed: {e}")
            failed.append(e)
            continue
        print(f"servo {servo_id}: version {_version(before)} -> {_version(after)}, "
              f"{len(image.data)} B in {time.monotonic() - started:.1f} s")
    if failed:
        return max(e.exit_code for e in failed)
    return 0


def cmd_image(args):
    from . import image as img

    data = img.make(args.binary, args.version, args.board, args.output)
    header = img.parse(data)
    print(f"{args.output}: {len(data)} B, version 0x{header.version:04x}, board 0x{header.board:04x}")
    return 0


def cmd_sim(args):
    """Runs servo_sim until Ctrl-C or SIGTERM; either stops it cleanly and
    removes a state folder it made."""
    import signal

    from .sim import Simulator

    tcp_port = args.tcp if args.tcp else None
    sim = Simulator(ids=args.ids or [1], tcp=args.tcp is not None, link=args.link,
                    state_dir=args.state, tcp_port=tcp_port)
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        sim.start()
        print(f"simulator running: bus {sim.url}, control 127.0.0.1:{sim.control_port}", flush=True)
        print(f"  e.g. servoctl --port {sim.url} scan --last 10     (Ctrl-C stops it)", flush=True)
        sim.process.wait()
    except KeyboardInterrupt:
        pass
    finally:
        sim.stop()
        signal.signal(signal.SIGTERM, previous)
    print("simulator stopped")
    return 0


# ---- argument parsing -------------------------------------------------------

def build_parser():
    ap = argparse.ArgumentParser(prog="servoctl", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--port", default=os.environ.get("SERVOCTL_PORT"),
                    help="serial port or pyserial URL (socket://HOST:PORT); env SERVOCTL_PORT")
    ap.add_argument("--baud", type=_baud, default=115200,
                    help=f"bits/s, one of item 36's: {', '.join(map(str, registers.BAUD_RATES.values()))}")
    ap.add_argument("--timeout", type=_reply_timeout, default=0.1,
                    help="reply timeout, seconds (0.001..10)")
    ap.add_argument("--version", action="version", version=f"servoctl {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)

    c = sub.add_parser("scan", help="find servos by pinging IDs")
    c.add_argument("--first", type=id_number, default=0)
    c.add_argument("--last", type=id_number, default=p.MAX_ID)
    c.add_argument("--all-bauds", action="store_true", help="every baud rate of item 36 in turn")
    c.add_argument("--reply-timeout", type=finite, default=None,
                   help="seconds per ID (default: from the baud rate, about 4 ms at 115200)")
    c.add_argument("--json", action="store_true", help="the servos found, as JSON")
    c.set_defaults(run=cmd_scan)

    c = sub.add_parser("ping", help="is this servo there")
    c.add_argument("id", type=int)
    c.add_argument("--json", action="store_true")
    c.set_defaults(run=cmd_ping)

    c = sub.add_parser("info", help="status area decoded: V, A, W, degC, status bits")
    c.add_argument("id", type=int)
    c.add_argument("--json", action="store_true", help="as one JSON object, SI units")
    c.set_defaults(run=cmd_info)

    c = sub.add_parser("id", help="IDs by serial number: assign SERIAL ID; bringup numbers new "
                                  "servos connected one at a time")
    c.add_argument("action", choices=["assign", "bringup"])
    c.add_argument("rest", nargs="*", help="assign: SERIAL ID")
    c.add_argument("--from-id", type=id_number, default=0, help="bringup: the new servos' ID (default 0)")
    c.add_argument("--first", type=id_number, default=1, help="bringup: the first ID to give (default 1)")
    c.add_argument("--count", type=int, default=1, help="bringup: how many servos (default 1)")
    c.add_argument("--wait-s", type=finite, default=60.0,
                   help="bringup: seconds to wait for each servo (default 60)")
    c.set_defaults(run=cmd_id)

    c = sub.add_parser("bench", help="Sync Monitor rounds a second and update time, against the "
                                     "wire's limit")
    c.add_argument("--ids", type=id_number, nargs="+", required=True, help="the servos to monitor")
    c.add_argument("--seconds", type=finite, default=3.0, help="of Sync Monitor rounds (default 3)")
    c.add_argument("--update-id", type=id_number, help="also time an update of this servo")
    c.add_argument("--image", help="the update image (default: a stand-in for the simulator)")
    c.add_argument("--image-size", type=int, default=20480, help="the stand-in's code bytes")
    c.add_argument("--json", action="store_true", help="one JSON object per figure")
    c.set_defaults(run=cmd_bench)

    c = sub.add_parser("store", help="the config store's health; answers dropped and bytes lost "
                                     "to flash work")
    c.add_argument("id", type=int)
    c.add_argument("--json", action="store_true", help="as one JSON object")
    c.set_defaults(run=cmd_store)

    c = sub.add_parser("config", help="the user area by name: get, set, dump, save, load, reset, diff")
    c.add_argument("action", choices=["get", "set", "dump", "save", "load", "reset", "diff"])
    c.add_argument("id", help="a servo ID (diff: an ID, a config or backup file, or 'factory')")
    c.add_argument("rest", nargs="*",
                   help="get NAME | set NAME VALUE | save FILE | load FILE | diff ID|FILE|factory")
    c.add_argument("--with-link", action="store_true",
                   help="config load: also set the ID and baud rate from the file")
    c.add_argument("--raw", action="store_true",
                   help="get/set/dump in protocol units (0.1 deg, NTC ADC, baud code); "
                        "load: a file of plain protocol numbers")
    c.add_argument("--json", action="store_true",
                   help="get/dump/diff as JSON (dump: the config file's form; raw with --raw)")
    c.set_defaults(run=cmd_config)

    def motion_options(c):
        c.add_argument("id", type=int)
        c.add_argument("angle", type=finite, help="degrees")
        g = c.add_mutually_exclusive_group()
        g.add_argument("--interval", type=int, help="ms to get there (default 1000)")
        g.add_argument("--velocity", type=finite, help="peak speed, deg/s")
        c.add_argument("--acc", type=int, help="acceleration ramp, ms (>= 20; default 20)")
        c.add_argument("--dec", type=int, help="deceleration ramp, ms (>= 20; default 20)")
        c.add_argument("--power", type=int, default=0, help="mW; 0 = the power limit (42)")
        c.add_argument("--multi-turn", action="store_true")

    def tolerance_option(c):
        c.add_argument("--tolerance", type=finite, default=outcome.TOLERANCE_DEG,
                       help=f"degrees the horn may be off (default {outcome.TOLERANCE_DEG})")

    c = sub.add_parser("move", help="an angle move (every angle mode)")
    motion_options(c)
    c.add_argument("--wait", action="store_true",
                   help="wait until the horn has arrived; exit 1 and say why if it does not")
    tolerance_option(c)
    c.add_argument("--timeout-s", type=finite, default=None,
                   help="give up after this (default: twice the plan, soft start, 2 s)")
    c.set_defaults(run=cmd_move)

    c = sub.add_parser("wheel", help="wheel mode: stop, run, turns, time")
    c.add_argument("id", type=int)
    c.add_argument("action", choices=["stop", "run", "turns", "time"])
    c.add_argument("--speed", type=int, default=90, help="deg/s")
    c.add_argument("--value", type=int, default=0, help="turns or ms")
    c.add_argument("--cw", action="store_true", help="clockwise (default counter-clockwise)")
    c.set_defaults(run=cmd_wheel)

    c = sub.add_parser("damping", help="damping mode")
    c.add_argument("id", type=int)
    c.add_argument("--power", type=int, default=0, help="mW")
    c.set_defaults(run=cmd_damping)

    c = sub.add_parser("stop", help="stop: release, hold or damping")
    c.add_argument("id", type=int)
    c.add_argument("--mode", choices=["release", "hold", "damping"], default="release")
    c.add_argument("--power", type=int, default=0, help="mW, for damping")
    c.set_defaults(run=cmd_stop)

    c = sub.add_parser("origin", help="make here angle 0 (only while released)")
    c.add_argument("id", type=int)
    c.add_argument("--reset-turns", action="store_true", help="only drop the whole turns")
    c.set_defaults(run=cmd_origin)

    c = sub.add_parser("monitor", help="live table (and plot) of angle, speed, V, A, W, degC, status")
    c.add_argument("ids", type=id_number, nargs="+")
    c.add_argument("--every", type=finite, default=0.2, help="seconds between samples")
    c.add_argument("--count", type=int, default=0, help="samples to take (0: until Ctrl-C)")
    c.add_argument("--sync", action="store_true", help="one Sync Monitor frame for all the servos")
    c.add_argument("--json", action="store_true", help="one JSON object per servo and sample")
    c.add_argument("--plot", action="store_true", help="a live plot window")
    c.add_argument("--plot-file", help="save the plot of the whole run here at the end (PNG)")
    c.set_defaults(run=cmd_monitor)

    c = sub.add_parser("record", help="record a move: CSV and PNG against the plan")
    motion_options(c)
    c.add_argument("--out", default="record", help="file name prefix (default: record)")
    c.add_argument("--settle", type=int, default=300, help="ms to keep sampling after the plan")
    tolerance_option(c)
    c.set_defaults(run=cmd_record)

    c = sub.add_parser("sync-move", help="several servos start their moves in one frame")
    c.add_argument("targets", type=_target, nargs="+", metavar="ID:DEGREES")
    c.add_argument("--interval", type=int, default=1000, help="ms to get there (default 1000)")
    c.add_argument("--power", type=int, default=0, help="mW; 0 = each servo's power limit")
    c.add_argument("--multi-turn", action="store_true",
                   help="every target is a multi-turn angle (without it, each is within -180..180)")
    c.set_defaults(run=cmd_sync_move)

    c = sub.add_parser("broadcast-move", help="every servo on the bus to one angle")
    c.add_argument("angle", type=finite, help="degrees, -180..180")
    c.add_argument("--interval", type=int, default=1000, help="ms to get there (default 1000)")
    c.add_argument("--power", type=int, default=0, help="mW; 0 = each servo's power limit")
    c.add_argument("--ids", type=id_number, nargs="+",
                   help="the servos on the bus, each checked before the broadcast (default: scan)")
    c.set_defaults(run=cmd_broadcast_move)

    c = sub.add_parser("async", help="begin: servos buffer moves; end: all start; cancel: drop")
    c.add_argument("action", choices=["begin", "end", "cancel"])
    c.set_defaults(run=cmd_async)

    c = sub.add_parser("backup", help="every servo's user area to one file")
    c.add_argument("file")
    c.add_argument("--ids", type=id_number, nargs="+", help="these servos (default: scan)")
    c.set_defaults(run=cmd_backup)

    c = sub.add_parser("restore", help="write a backup back, each servo by its ID")
    c.add_argument("file")
    c.add_argument("--with-link", action="store_true", help="also set IDs and baud rates")
    c.set_defaults(run=cmd_restore)

    c = sub.add_parser("update", help="write a firmware image into servos over the bus "
                                      "(also recovers a servo left in its bootloader)")
    c.add_argument("targets", nargs="+", metavar="ID|IMAGE",
                   help="the servo IDs and the update image (servoctl image), in either order")
    c.add_argument("--catch", type=float, default=0, metavar="SECONDS",
                   help="first wait this long for the servo's bootloader: power the servo up "
                        "meanwhile (recovers a servo whose application does not answer)")
    c.set_defaults(run=cmd_update)

    c = sub.add_parser("image", help="make an update image from an application binary")
    c.add_argument("binary", help="the application from its vector table (objcopy -O binary)")
    c.add_argument("--version", required=True, help="firmware version, data item 7 (e.g. 0x0011)")
    c.add_argument("--board", required=True, help="a board of firmware/boards (stm32f103, stm32f030k6, qemu_stm32vl, host_sim) or its number")
    c.add_argument("-o", "--output", required=True)
    c.set_defaults(run=None)

    c = sub.add_parser("sim", help="run the simulator")
    c.add_argument("--id", dest="ids", type=int, action="append")
    c.add_argument("--tcp", type=int, nargs="?", const=0, default=None, metavar="PORT",
                   help="a TCP port instead of a pty (any free port if none given)")
    c.add_argument("--link", help="symlink to the pty")
    c.add_argument("--state", help="folder for the flash files")
    c.set_defaults(run=None)
    return ap


def main(argv=None, clock=None) -> int:
    """The one boundary where every error becomes a line and an exit code.
    clock: the bus's clock (protocol.Bus), the host's if None; a simulator
    passes its own (servoctl.sim.Simulator.clock_s)."""
    args = build_parser().parse_args(argv)
    try:
        return _run(args, clock)
    except ServoError as e:
        print(f"servoctl: error: {e}", file=sys.stderr)
        return e.exit_code
    except KeyboardInterrupt:
        print("servoctl: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def _run(args, clock=None) -> int:
    if args.command == "sim":
        return cmd_sim(args)
    if args.command == "image":
        return cmd_image(args)
    if args.command == "config":
        need = {"get": 1, "set": 2, "dump": 0, "save": 1, "load": 1, "reset": 0, "diff": 1}[args.action]
        if len(args.rest) != need:
            raise UsageError(f"config {args.action} takes {need} argument(s)")
        args.target, args.other = args.id, args.rest[0] if args.action == "diff" else None
        if args.action != "diff":
            try:
                args.id = id_number(args.id)
            except argparse.ArgumentTypeError as e:
                raise UsageError(str(e)) from None
        args.name = args.rest[0] if args.action in ("get", "set") else None
        args.value = args.rest[1] if args.action == "set" else None
        args.file = args.rest[0] if args.action in ("save", "load") else None
    if not args.port:
        raise UsageError("no port: give --port or set SERVOCTL_PORT")
    with Bus(args.port, args.baud, args.timeout, clock=clock) as bus:
        try:
            return args.run(bus, args)
        except BadAnswer:
            raise
        except NoReply:
            # A servo in its bootloader answers Ping and the update packets
            # only: say so, and what recovers it, instead of "no reply".
            servo_id = getattr(args, "id", None)
            if isinstance(servo_id, int) and args.command not in ("update", "ping"):
                why = scan.in_bootloader(bus, servo_id)
                if why:
                    raise NoReply(why) from None
            raise


if __name__ == "__main__":
    sys.exit(main())
