"""servoctl's commands, each given the bus and the parsed arguments (args.py,
which also holds the description --help shows), and main(), which turns
every error into one line and an exit code."""
import argparse
import json
import os
import sys
import time

from . import args as args_
from . import checks, config_diff, config_file, console, frame, group, ids, link_rate, ntc, outcome, registers, scan, units
from . import protocol as p
from .args import build_parser
from .errors import BadAnswer, NoReply, Refused, ServoError, UsageError
from .protocol import Bus
from .record import check_writable, cmd_record
from .stream import cmd_stream
from .faults import cmd_faults
from .info import cmd_info
from .servo import Servo

EXIT_INTERRUPTED = 130


def fmt_status(status: int) -> str:
    names = registers.status_names(status)
    return ", ".join(names) if names else "ok"


# ---- commands --------------------------------------------------------------

def cmd_scan(bus, args):
    from .console import progress as Progress  # a closed pipe ends quietly (main)

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
                scan.wake(bus)  # no servo is missed for a page erase
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
        print(scan.count_line(found), "(interrupted)" if interrupted else "")
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
    print(f"servo {args.id}: no reply" + link_rate.no_reply_hint(bus, args.port, args.sim_control, bus.serial.baudrate))
    return NoReply.exit_code


def cmd_id(bus, args):
    if args.action == "assign":
        if len(args.rest) != 2:
            raise UsageError("id assign takes SERIAL ID (scan shows serial numbers)")
        serial, new_id = ids.serial_number(args.rest[0]), args_.id_number(args.rest[1])
        ids.assign(bus, serial, new_id)
        print(f"servo serial 0x{serial:08x} is now ID {new_id}")
        return 0
    if args.rest:
        raise UsageError("id bringup takes no arguments: --from-id, --first, --count, --wait-s")
    done = ids.bring_up(bus, args.from_id, args.first, args.count, args.wait_s,
                        lambda line: print(line, flush=True))
    print(f"{len(done)} servo(s) numbered: " + ", ".join(f"0x{s:08x} -> {i}" for s, i in done))
    return 0


def cmd_identify(bus, args):
    from .identify import cmd_identify as identify  # scipy: loaded for this command alone

    return identify(bus, args)


def cmd_calibrate(bus, args):
    from .calibrate import cmd_calibrate as calibrate  # scipy (identify's come_to_rest): this command alone

    return calibrate(bus, args)


def cmd_tune(bus, args):
    from .tune import cmd_tune as tune  # scipy (identify): loaded for this command alone

    return tune(bus, args)


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
    for item in registers.STORED + registers.RAM:
        if item.name in values:
            ram = "  (RAM: lost at power-up)" if item in registers.RAM else ""
            print(f"  {item.id:2d} {item.name:<18} {_shown(item, values[item.name], as_raw)}{ram}")


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
        link_rate.after_set(bus, args, item.name, value)
    elif args.action == "dump":
        values = config_file.settable(s)
        if args.json:
            print(json.dumps(values if args.raw else config_file.config_json(values, config_file.servo_of(s))))
        else:
            _print_config(values, args.raw)
    elif args.action == "save":
        print(config_file.save(args.file, s))
    elif args.action == "load":
        entry = config_file.parse_config(config_file.read(args.file), args.file, args.raw)
        serial, baud = s.read("serial"), s.read("baud")  # before: the load may move the servo
        kept = group.write_user_area(s, entry.values, args.with_link)  # validated before sending
        notes = link_rate.after_load(bus, args, s.id, baud, entry.values.get("baud", baud))
        notes += [f"kept {', '.join(f'{k} {s.read(k)}' for k in kept)}; --with-link to change"] if kept else []
        notes += [f"{n} in RAM: lost at power-up"] if (n := sum(i.name in entry.values for i in registers.RAM)) else []
        if entry.raw:
            notes.append("a raw file: protocol units")
        if entry.serial is not None and entry.serial != serial:
            notes.append(f"the file is servo serial 0x{entry.serial:08x}'s")
        print(f"loaded {len(entry.values)} item(s) from {args.file} into servo {args.id}" + " (%s)" % "; ".join(notes) * bool(notes))
    elif args.action == "reset":
        s.reset_user_data()
        print(f"servo {args.id}: user area reset (ID and baud rate kept)")
    return 0


def cmd_move(bus, args):
    s = Servo(bus, args.id)
    request = args_.move_request(args)
    asked = args_.decideg(args.angle)
    where = frame.check_target(s, asked, args.multi_turn)
    if args.velocity is not None and (why := checks.speed_warning(args.velocity, s.read("voltage"))):
        print(f"servoctl: {why}", file=sys.stderr)
    plan = outcome.plan_move(s, asked, request, where) if args.wait else None
    s.send_move(asked, request)
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
        check_writable(args.plot_file)
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


def _interrupt(signum, frame):
    raise KeyboardInterrupt


def _version(v) -> str:
    return "none" if v is None else f"0x{v:04x}"


def cmd_update(bus, args):
    from rich.progress import BarColumn, DownloadColumn, TextColumn, TimeRemainingColumn

    from . import image as img
    from . import update as upd
    from .console import progress as Progress

    # `update IMAGE ID...` or `update ID... IMAGE`: the image is the one
    # that is not a number.
    ids, images = [], []
    for arg in args.targets:
        (ids if arg.isascii() and arg.isdigit() else images).append(arg)
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
                    state_dir=args.state, tcp_port=tcp_port, plant=args.plant,
                    board=None if args.board == "host" else args.board, host_link=args.host_link)
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        sim.start()
        print(f"simulator running: bus {sim.url}, control 127.0.0.1:{sim.control_port}", flush=True)
        print(f"  e.g. servoctl --port {sim.url} --sim-control {sim.control_port} scan  (Ctrl-C stops)", flush=True)
        sim.process.wait()
    except KeyboardInterrupt:
        pass
    finally:
        sim.stop()
        signal.signal(signal.SIGTERM, previous)
    print("simulator stopped")
    return 0


# ---- argument parsing -------------------------------------------------------

# Each subcommand's function (image and sim need no bus: _run starts them).
COMMANDS = {
    "scan": cmd_scan,
    "ping": cmd_ping,
    "info": cmd_info,
    "faults": cmd_faults,
    "id": cmd_id,
    "bench": cmd_bench,
    "store": cmd_store,
    "config": cmd_config,
    "move": cmd_move,
    "wheel": cmd_wheel,
    "damping": cmd_damping,
    "stop": cmd_stop,
    "origin": cmd_origin,
    "monitor": cmd_monitor,
    "record": cmd_record,
    "stream": cmd_stream,
    "identify": cmd_identify,
    "tune": cmd_tune,
    "calibrate": cmd_calibrate,
    "sync-move": cmd_sync_move,
    "broadcast-move": cmd_broadcast_move,
    "async": cmd_async,
    "backup": cmd_backup,
    "restore": cmd_restore,
    "update": cmd_update,
}


def main(argv=None, clock=None) -> int:
    """The one boundary where every error becomes a line and an exit code.
    clock: the bus's clock (protocol.Bus), the host's if None; a simulator
    passes its own (servoctl.sim.Simulator.clock_s)."""
    args = build_parser().parse_args(argv)
    try:
        with console.pipe_guard(args):  # a command that changes servos finishes
            code = _run(args, clock)
        sys.stdout.flush()  # a reader that stopped reading is met here, not at exit
        return code
    except ServoError as e:
        print(f"servoctl: error: {e}", file=sys.stderr)
        return e.exit_code
    except argparse.ArgumentTypeError as e:  # a value checked after parsing (id assign's ID)
        print(f"servoctl: error: {e}", file=sys.stderr)
        return UsageError.exit_code
    except KeyboardInterrupt:
        print("servoctl: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # `servoctl info 2 | head -3`: the reader has what it wanted, quietly.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


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
                args.id = args_.id_number(args.id)
            except argparse.ArgumentTypeError as e:
                raise UsageError(str(e)) from None
        args.name = args.rest[0] if args.action in ("get", "set") else None
        args.value = args.rest[1] if args.action == "set" else None
        args.file = args.rest[0] if args.action in ("save", "load") else None
    if not args.port:
        raise UsageError("no port: give --port or set SERVOCTL_PORT")
    baud = link_rate.open_rate(args.port, args.baud, args.sim_control)
    with Bus(args.port, baud, args.timeout, clock=clock) as bus:
        try:
            return COMMANDS[args.command](bus, args)
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
            raise NoReply(f"{sys.exc_info()[1]}{link_rate.no_reply_hint(bus, args.port, args.sim_control, baud)}") from None


if __name__ == "__main__":
    sys.exit(main())
