"""servoctl's entry point: main() parses the command line (args.py, which
also holds the description --help shows and the operands' rules), runs the
command's function from its module (COMMANDS) with the bus, and turns
every error into one line and an exit code."""
import argparse
import os
import sys

from . import args as args_
from . import console, extras, link_rate, scan
from .args import build_parser
from .cmd_bus import cmd_bench, cmd_id, cmd_ping, cmd_scan
from .cmd_config import cmd_config, cmd_store
from .cmd_drive import cmd_calibrate, cmd_identify, cmd_tune
from .cmd_group import cmd_async, cmd_backup, cmd_broadcast_move, cmd_restore, cmd_sync_move
from .cmd_monitor import cmd_monitor
from .cmd_motion import cmd_damping, cmd_move, cmd_origin, cmd_stop, cmd_wheel
from .cmd_sim import cmd_sim
from .cmd_ui import cmd_ui
from .cmd_update import cmd_image, cmd_update
from .errors import EXIT_INTERRUPTED, BadAnswer, NoReply, ServoError, UsageError
from .faults import cmd_faults
from .info import cmd_info
from .protocol import Bus
from .record import cmd_record
from .stream import cmd_stream

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
    "ui": cmd_ui,
}


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
    if args.command == "sim":
        return cmd_sim(args)
    if args.command == "image":
        return cmd_image(args)
    if args.command == "config":
        args_.config_operands(args)
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
        return run_command(bus, args)


def run_command(bus, args) -> int:
    """One parsed command on an open bus (servoctl ui runs its page's
    requests here too): a silent servo's NoReply says why it may be."""
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
        raise NoReply(f"{sys.exc_info()[1]}{link_rate.no_reply_hint(bus, args.port, args.sim_control, bus.serial.baudrate)}") from None


if __name__ == "__main__":
    sys.exit(main())
