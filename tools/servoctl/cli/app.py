"""servoctl's command line: main() parses it (args.py, which also holds
the description --help shows and the operands' rules), runs the command's
function with the bus (COMMANDS: commands.py's, and ui's) and turns every
error into one line and an exit code."""
import argparse
import os
import sys

from .. import extras, link_rate
from ..errors import EXIT_INTERRUPTED, ServoError, UsageError
from ..protocol import Bus
from . import args as args_
from . import cmd_sim, cmd_ui, cmd_update, commands, console
from .args import build_parser

# Each subcommand's function by its name: commands.py's, and ui, which
# serves a page that runs those (ui/worker.py); image and sim need no bus,
# they start what they need themselves (_run).
COMMANDS = {**commands.COMMANDS, **cmd_ui.COMMANDS}
NO_BUS = {**cmd_sim.NO_BUS, **cmd_update.NO_BUS}


def main(argv=None, clock=None) -> int:
    """The one boundary where every error becomes a line and an exit code.
    clock: the bus's clock (protocol.Bus); if None, the simulator's given
    --sim-control (link_rate.simulator), else the host's; a simulator
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
    except ModuleNotFoundError as e:  # an optional part's library (servoctl.extras)
        if extras.missing_text(e.name) is None:
            raise
        print(f"servoctl: error: {extras.missing_text(e.name)}", file=sys.stderr)
        return UsageError.exit_code
    except KeyboardInterrupt:
        print("servoctl: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # `servoctl info 2 | head -3`: the reader has what it wanted, quietly.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


def _run(args, clock=None) -> int:
    if args.command in NO_BUS:
        return NO_BUS[args.command](args)
    if args.command == "config":
        args_.config_operands(args)
    extras.require(*commands.EXTRAS.get(args.command, ()))  # before the port: its extra named first
    if not args.port:
        raise UsageError("no port: give --port or set SERVOCTL_PORT")
    baud = link_rate.open_rate(args.port, args.baud, args.sim_control)
    sim = None if clock else link_rate.simulator(args.sim_control)
    try:
        return _on_bus(args, baud, clock or (sim and sim.clock_s))
    finally:
        if sim is not None:
            sim.stop()  # its clock's connection


def _on_bus(args, baud, clock) -> int:
    with Bus(args.port, baud, args.timeout, clock=clock) as bus:
        return commands.run_command(bus, args, COMMANDS)
