"""servoctl monitor: several servos sampled live, as a table, JSON lines or
a plot (live.py; loaded for this command alone)."""
import os
import sys

from .. import extras
from ..errors import EXIT_INTERRUPTED, NoReply
from .cmd_record import check_writable


def cmd_monitor(bus, args):
    from .live import has_display, monitor

    if args.plot_file:
        check_writable(args.plot_file)
    plot = args.plot
    if plot and not has_display():
        print("servoctl: warning: --plot: no display (DISPLAY and WAYLAND_DISPLAY are unset), so no "
              "window; sampling without it. --plot-file FILE saves the plot instead", file=sys.stderr)
        plot = False
    if plot or args.plot_file:
        extras.require("matplotlib")  # not a run sampled for a plot it cannot draw
    never, interrupted = {}, False
    try:
        never = monitor(bus, args.ids, args.every, args.count, args.sync, args.json, plot, args.plot_file)
    except KeyboardInterrupt:  # the way to stop a monitor: its plot still saved, then 130
        interrupted = True
    if args.plot_file:
        print(f"plot {os.path.abspath(args.plot_file)}", file=sys.stderr if args.json else sys.stdout)
    if interrupted:
        print("servoctl: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    if never:
        raise NoReply("; ".join(why or f"servo {i} never answered" for i, why in sorted(never.items())))
    return 0


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "monitor": cmd_monitor,
}
