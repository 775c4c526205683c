"""servoctl's commands that find the servos on a bus and number them (scan,
ping, id) and measure what the bus carries (bench)."""
import json
import sys

from . import args as args_
from .. import ids, link_rate, registers, scan
from ..errors import EXIT_INTERRUPTED, NoReply, Refused
from ..servo import Servo


def cmd_scan(bus, args):
    from .console import progress as Progress  # a closed pipe ends quietly (main)

    rates = [bus.serial.baudrate]  # the one asked for first
    if args.all_bauds and link_rate.is_socket(bus.port) and not args.sim_control:
        print("servoctl: socket:// carries no baud rate (the far end sets it): scanning once; "
              "give --sim-control PORT and a simulator's host rate is swept", file=sys.stderr)
    elif args.all_bauds:
        rates += [r for r in sorted(registers.BAUD_RATES.values()) if r != rates[0]]
    found = []
    interrupted = False
    with Progress(transient=True, disable=not sys.stderr.isatty()) as progress, \
            link_rate.restored(bus, args.sim_control):
        task = progress.add_task("scanning", total=len(rates) * (args.last - args.first + 1))
        try:
            for rate in rates:
                link_rate.set_rate(bus, args.sim_control, rate)
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
        print(scan.count_line(found) + (" (interrupted)" if interrupted else ""))
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
    garbled = bus.stray_bytes + bus.bad_frames
    if Servo(bus, args.id).ping():
        print(f"servo {args.id}: answered")
        return 0
    if bus.stray_bytes + bus.bad_frames > garbled:  # bytes came, no whole answer
        print(f"servo {args.id}: garbled answer: two or more servos may share ID {args.id}; "
              f"see 'servoctl scan'")
        return Refused.exit_code
    print(f"servo {args.id}: no reply" + link_rate.no_reply_hint(bus, args.port, args.sim_control, bus.serial.baudrate))
    return NoReply.exit_code


def cmd_id(bus, args):
    operands = args_.id_operands(args)
    if args.action == "assign":
        serial, new_id = operands
        ids.assign(bus, serial, new_id)
        print(f"servo serial 0x{serial:08x} is now ID {new_id}")
        return 0
    done = ids.bring_up(bus, args.from_id, args.first, args.count, args.wait_s,
                        lambda line: print(line, flush=True))
    print(f"{len(done)} servo(s) numbered: " + ", ".join(f"0x{s:08x} -> {i}" for s, i in done))
    return 0


def cmd_bench(bus, args):
    from .. import image as img
    from . import bench

    figures = [bench.sync_monitor_rounds(bus, args.ids, args.seconds)]
    if args.update_id is not None:
        image = (img.load(args.image) if args.image else
                 bench.image_of_size(args.image_size, 0x0010, img.BOARDS["host_sim"]))
        figures.append(bench.update_time(bus, args.update_id, image))
    for f in figures:
        print(json.dumps({"what": f.what, "measured": f.measured, "limit": f.limit, "unit": f.unit,
                          "ratio": f.ratio}) if args.json else f.line())
    return 0


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "scan": cmd_scan,
    "ping": cmd_ping,
    "id": cmd_id,
    "bench": cmd_bench,
}
