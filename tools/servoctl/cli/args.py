"""The command line of servoctl: its parser, the argparse types that check
a value, and the rules of a command's operands that argparse cannot say:
all checked before anything is sent."""
import argparse
import dataclasses
import math
import os

from .. import __version__, ids, outcome, registers, units
from . import args_drive
from .. import protocol as p
from ..checks import MIN_RAMP_MS, scaled
from ..errors import UsageError
from ..move_request import MoveRequest

# The most tracking error (RMS) `servoctl stream` takes for a servo that followed its file (docs/streaming.md).
STREAM_TOLERANCE_DEG = 1.0

# The description servoctl --help shows.
DESCRIPTION = """servoctl: talk to a UART bus servo on a serial port or the simulator.

Angles are given in degrees and speeds in degrees per second; the tool turns
them into the protocol's 0.1 degree units and checks every value before
anything is sent.

Exit codes: 0 done; 1 the servo refused, or a move did not arrive (why is
said); 2 a usage error (nothing was sent); 3 no reply; 4 the serial link
failed; 5 a cut-short command left an item changed; 130 interrupted (Ctrl-C)."""


def _baud(text: str) -> int:
    """--baud: a rate the servos speak (data item 36)."""
    rates = registers.BAUD_RATES.values()
    if text.isascii() and text.isdigit() and int(text) in rates:
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
    return scaled(degrees, 10, "angle")


def move_request(args) -> MoveRequest:
    """Packet choice: --velocity: 12/15; --interval with --acc or --dec:
    11/14; --interval alone: the plain angle modes 8/13."""
    by_velocity = args.velocity is not None
    return MoveRequest(
        acc_ms=MIN_RAMP_MS if args.acc is None else args.acc,
        dec_ms=MIN_RAMP_MS if args.dec is None else args.dec,
        power_mw=args.power, multi_turn=args.multi_turn,
        velocity=decideg(args.velocity) if by_velocity else None,
        interval_ms=None if by_velocity else (1000 if args.interval is None else args.interval),
        ramps=by_velocity or args.acc is not None or args.dec is not None)


def id_number(text: str) -> int:
    """argparse type: a servo ID, 0..254."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a servo ID: {text!r}") from None
    if not 0 <= value <= p.MAX_ID:
        raise argparse.ArgumentTypeError(f"servo IDs are 0..{p.MAX_ID}, not {value}")
    return value


def power_mw(text: str) -> int:
    """argparse type: a power with its unit, as config set takes data item
    42 ("2.5W", "2500mW"); 0 alone is the servo's power limit. A bare
    number is refused: 3 meant 3 mW to the tool and 3 W to its user."""
    if text.strip() in ("0", "0.0"):
        return 0
    item = dataclasses.replace(registers.find("power_limit"), name="--power")
    try:
        return units.to_raw(item, text)
    except p.ServoError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def finite(text: str) -> float:
    """argparse type: a real number of degrees (no nan, no inf)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


def _target(text: str):
    """ID:DEGREES, for sync-move."""
    servo_id, sep, degrees = text.partition(":")
    try:
        if not sep:
            raise ValueError
        return int(servo_id), finite(degrees)
    except (ValueError, argparse.ArgumentTypeError):
        raise argparse.ArgumentTypeError(f"not ID:DEGREES: {text!r}") from None


# ---- operand rules: what argparse cannot say of a command's operands,
# checked by the command before anything is sent ----------------------------

def id_operands(args):
    """id assign SERIAL ID: (serial, new ID); id bringup: no operands."""
    if args.action == "assign":
        if len(args.rest) != 2:
            raise UsageError("id assign takes SERIAL ID (scan shows serial numbers)")
        return ids.serial_number(args.rest[0]), id_number(args.rest[1])
    if args.rest:
        raise UsageError("id bringup takes no arguments: --from-id, --first, --count, --wait-s")
    return None


def config_operands(args) -> None:
    """config ACTION ID REST...: the operands by name on args (target,
    other, id, name, value, file), each action's count checked."""
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


def raw_value(item, text: str) -> int:
    """config set --raw: a whole number in protocol units."""
    try:
        return int(text, 0)
    except ValueError:
        raise UsageError(f"{item.name} takes a whole number in protocol units, "
                         f"not {text!r}") from None


def distinct_targets(targets) -> dict:
    """sync-move's ID:DEGREES: {id: degrees}, one target a servo."""
    ids_ = [servo_id for servo_id, _ in targets]
    twice = sorted({i for i in ids_ if ids_.count(i) > 1})
    if twice:
        raise UsageError(f"servo {', '.join(map(str, twice))} is given more than one target")
    return dict(targets)


def update_operands(targets) -> tuple:
    """`update IMAGE ID...` or `update ID... IMAGE`: the image is the one
    that is not a number. ([IDs], image)."""
    ids_, images = [], []
    for arg in targets:
        (ids_ if arg.isascii() and arg.isdigit() else images).append(arg)
    if len(images) != 1 or not ids_:
        raise UsageError("update takes one image and one or more servo IDs")
    for servo_id in ids_:
        if not 0 <= int(servo_id) <= p.MAX_ID:
            raise UsageError(f"servo ID {servo_id} is not 0-{p.MAX_ID}")
    return [int(i) for i in ids_], images[0]


class _TreeBoards:
    """The boards of the firmware tree servoctl finds (servo_image.boards()),
    named when a help text is printed: a help's %(boards)s, read then, so no
    other command pays for reading the boards' board.h."""

    def __str__(self) -> str:
        from .. import image
        return ", ".join(image.boards()) or "none: no firmware tree found; set SERVO_FIRMWARE_ROOT"


def build_parser():
    ap = argparse.ArgumentParser(prog="servoctl", description=DESCRIPTION,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--port", default=os.environ.get("SERVOCTL_PORT"),
                    help="serial port or pyserial URL (socket://HOST:PORT); env SERVOCTL_PORT")
    ap.add_argument("--baud", type=_baud, default=None,
                    help=f"bits/s, one of item 36's: {', '.join(map(str, registers.BAUD_RATES.values()))} "
                         f"(default 115200; on socket:// set through --sim-control)")
    ap.add_argument("--sim-control", default=os.environ.get("SERVOCTL_SIM_CONTROL"), metavar="PORT",
                    help="a simulator's control port: servoctl sets its host baud rate there for "
                         "--baud and a baud change on socket://; env SERVOCTL_SIM_CONTROL")
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

    c = sub.add_parser("ping", help="is this servo there")
    c.add_argument("id", type=int)
    c.add_argument("--json", action="store_true")

    c = sub.add_parser("info", help="status area decoded: V, A, W, degC, status bits; the winding's "
                       "temperature, what limits the output, the watchdog")
    c.add_argument("id", type=int)
    c.add_argument("--json", action="store_true", help="as one JSON object, SI units")

    c = sub.add_parser("faults", help="the fault history, newest first (kept across power cycles)")
    c.add_argument("id", type=int)
    c.add_argument("--clear", action="store_true", help="clear the history")
    c.add_argument("--json", action="store_true", help="as one JSON object")
    c.add_argument("--elf", help="the image's ELF: names a firmware fault's code")

    c = sub.add_parser("id", help="IDs by serial number: assign SERIAL ID; bringup numbers new "
                                  "servos connected one at a time")
    c.add_argument("action", choices=["assign", "bringup"])
    c.add_argument("rest", nargs="*", help="assign: SERIAL ID")
    c.add_argument("--from-id", type=id_number, default=0, help="bringup: the new servos' ID (default 0)")
    c.add_argument("--first", type=id_number, default=1, help="bringup: the first ID to give (default 1)")
    c.add_argument("--count", type=int, default=1, help="bringup: how many servos (default 1)")
    c.add_argument("--wait-s", type=finite, default=60.0,
                   help="bringup: seconds to wait for each servo (default 60)")

    c = sub.add_parser("bench", help="Sync Monitor rounds a second and update time, against the "
                                     "wire's limit")
    c.add_argument("--ids", type=id_number, nargs="+", required=True, help="the servos to monitor")
    c.add_argument("--seconds", type=finite, default=3.0, help="of Sync Monitor rounds (default 3)")
    c.add_argument("--update-id", type=id_number, help="also time an update of this servo")
    c.add_argument("--image", help="the update image (default: a stand-in for the simulator)")
    c.add_argument("--image-size", type=int, default=20480, help="the stand-in's code bytes")
    c.add_argument("--json", action="store_true", help="one JSON object per figure")

    c = sub.add_parser("store", help="the config store's health; answers dropped and bytes lost "
                                     "to flash work")
    c.add_argument("id", type=int)
    c.add_argument("--json", action="store_true", help="as one JSON object")

    c = sub.add_parser("config", help="the user area by name: get, set, dump, save, load, reset, diff")
    c.add_argument("action", choices=["get", "set", "dump", "save", "load", "reset", "diff"])
    c.add_argument("id", help="a servo ID (diff: an ID, a config or backup file, or 'factory')")
    c.add_argument("rest", nargs="*",
                   help="get NAME | set NAME VALUE | save FILE | load FILE | diff ID|FILE|factory")
    c.add_argument("--with-link", action="store_true",
                   help="config load: also set the ID and baud rate from the file")
    c.add_argument("--with-calibration", action="store_true",
                   help="config load of another servo's file: also its calibration and drive train (80-91)")
    c.add_argument("--raw", action="store_true",
                   help="get/set/dump in protocol units (0.1 deg, NTC ADC, baud code); "
                        "load: a file of plain protocol numbers")
    c.add_argument("--json", action="store_true",
                   help="get/dump/diff as JSON (dump: the config file's form; raw with --raw)")

    def motion_options(c):
        c.add_argument("id", type=int)
        c.add_argument("angle", type=finite, help="degrees")
        g = c.add_mutually_exclusive_group()
        g.add_argument("--interval", type=int, help="ms to get there (default 1000)")
        g.add_argument("--velocity", type=finite, help="peak speed, deg/s")
        c.add_argument("--acc", type=int, help="acceleration ramp, ms (>= 20; default 20)")
        c.add_argument("--dec", type=int, help="deceleration ramp, ms (>= 20; default 20)")
        c.add_argument("--power", type=power_mw, default=0, help="2.5W or 2500mW; 0 = the power limit (42)")
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

    c = sub.add_parser("wheel", help="wheel mode: stop, run, turns, time")
    c.add_argument("id", type=int)
    c.add_argument("action", choices=["stop", "run", "turns", "time"])
    c.add_argument("--speed", type=int, default=90, help="deg/s")
    c.add_argument("--value", type=int, default=0, help="turns or ms")
    c.add_argument("--cw", action="store_true", help="clockwise (default counter-clockwise)")
    c.add_argument("--past-limits", action="store_true", help=args_drive.PAST_LIMITS)

    c = sub.add_parser("damping", help="damping mode")
    c.add_argument("id", type=int)
    c.add_argument("--power", type=power_mw, default=0, help="2.5W or 2500mW; 0 = the power limit (42)")

    c = sub.add_parser("stop", help="stop: release, hold or damping")
    c.add_argument("id", type=int)
    c.add_argument("--mode", choices=["release", "hold", "damping"], default="release")
    c.add_argument("--power", type=power_mw, default=0, help="for damping: 2.5W or 2500mW")

    c = sub.add_parser("origin", help="make here angle 0 (only while released)")
    c.add_argument("id", type=int)
    c.add_argument("--reset-turns", action="store_true", help="only drop the whole turns")
    c.add_argument("--past-limits", action="store_true",
                   help="though the angle limits are narrowed: they then name other horn positions until power-up")

    c = sub.add_parser("monitor", help="live table (and plot) of angle, speed, V, A, W, degC, status")
    c.add_argument("ids", type=id_number, nargs="+")
    c.add_argument("--every", type=finite, default=0.2, help="seconds between samples")
    c.add_argument("--count", type=int, default=0, help="samples to take (0: until Ctrl-C)")
    c.add_argument("--sync", action="store_true", help="one Sync Monitor frame for all the servos")
    c.add_argument("--json", action="store_true", help="one JSON object per servo and sample")
    c.add_argument("--plot", action="store_true", help="a live plot window")
    c.add_argument("--plot-file", help="save the plot of the whole run here at the end (PNG)")

    c = sub.add_parser("record", help="record a move: CSV and PNG against the plan")
    motion_options(c)
    c.add_argument("--out", default="record", help="file name prefix (default: record)")
    c.add_argument("--settle", type=int, default=300, help="ms to keep sampling after the plan")
    tolerance_option(c)

    c = sub.add_parser("stream", help="stream a trajectory (CSV: time s, one column of degrees per servo ID)")
    c.add_argument("file", help="CSV: a header 'time,ID,ID...', then evenly spaced rows")
    c.add_argument("--lead-in", type=float, default=1.0,
                   help="s to move to the first row first (default 1); waited for, soft start included")
    c.add_argument("--tolerance", type=finite, default=STREAM_TOLERANCE_DEG,
                   help=f"most tracking error (RMS, degrees) a servo may have; beyond it, or with the "
                        f"setpoints sent late, exit 1 (default {STREAM_TOLERANCE_DEG})")
    c.add_argument("--report-only", action="store_true",
                   help="print the figures and exit 0 however the servos followed")
    c.add_argument("--host-jitter-ms", type=finite, default=0.0, metavar="MS", help="model a host: rows sent ±MS")
    c.add_argument("--host-late-every", type=int, default=0, metavar="N", help="model a host: 1 row in N a period late")

    args_drive.add_commands(sub)

    c = sub.add_parser("sync-move", help="several servos start their moves in one frame")
    c.add_argument("targets", type=_target, nargs="+", metavar="ID:DEGREES")
    c.add_argument("--interval", type=int, default=1000, help="ms to get there (default 1000)")
    c.add_argument("--power", type=power_mw, default=0, help="2.5W or 2500mW; 0 = each servo's power limit")
    c.add_argument("--multi-turn", action="store_true",
                   help="every target is a multi-turn angle (without it, each is within -180..180)")

    c = sub.add_parser("broadcast-move", help="every servo on the bus to one angle")
    c.add_argument("angle", type=finite, help="degrees, -180..180")
    c.add_argument("--interval", type=int, default=1000, help="ms to get there (default 1000)")
    c.add_argument("--power", type=power_mw, default=0, help="2.5W or 2500mW; 0 = each servo's power limit")
    c.add_argument("--ids", type=id_number, nargs="+",
                   help="the servos on the bus, each checked before the broadcast (default: scan)")

    c = sub.add_parser("async", help="begin: servos buffer moves; end: all start; cancel: drop")
    c.add_argument("action", choices=["begin", "end", "cancel"])

    c = sub.add_parser("backup", help="every servo's user and drive areas, and RAM items, to one file")
    c.add_argument("file")
    c.add_argument("--ids", type=id_number, nargs="+", help="these servos (default: scan)")

    c = sub.add_parser("restore", help="write a backup back, each servo by its ID")
    c.add_argument("file")
    c.add_argument("--with-link", action="store_true", help="also set IDs and baud rates")

    c = sub.add_parser("update", help="write a firmware image into servos over the bus "
                                      "(also recovers a servo left in its bootloader)")
    c.add_argument("targets", nargs="+", metavar="ID|IMAGE",
                   help="the servo IDs and the update image (servoctl image), in either order")
    c.add_argument("--catch", type=float, default=0, metavar="SECONDS",
                   help="first wait this long for the servo's bootloader: power the servo up "
                        "meanwhile (recovers a servo whose application does not answer)")

    c = sub.add_parser("ui", help="the bench in a web browser: a page on this bus (bus, servo, motion, plots, "
                                  "bring-up); its address with its token is the first line; docs/ui.md")
    c.add_argument("--listen", type=int, default=0, metavar="PORT", help="TCP port (default: a free one)")
    c.add_argument("--bind", default="127.0.0.1", metavar="ADDR", help="address to listen on (default: this PC only)")
    c.add_argument("--no-browser", action="store_true", help="only print the address")
    c.add_argument("--files", metavar="DIR", help="the only folder the page's files are in (default: here)")

    c = sub.add_parser("image", help="make an update image from an application binary")
    c.add_argument("binary", help="the application from its vector table (objcopy -O binary)")
    c.add_argument("--version", required=True, help="firmware version, data item 7 (e.g. 0x0011)")
    c.add_argument("--board", required=True,
                   help="a board of firmware/boards (%(boards)s) or its number").boards = _TreeBoards()
    c.add_argument("-o", "--output", required=True)

    c = sub.add_parser("sim", help="run the simulator, or a virtual board (--board)")
    c.add_argument("--board", default="host", choices=["host", "stm32f103", "stm32f030k6", "stm32g031k8"],
                   help="host: servo_sim (the firmware built for the PC); stm32f103, stm32f030k6, stm32g031k8: "
                        "the board's shipped images on its emulated chip (tools/vboard)")
    c.add_argument("--id", dest="ids", type=int, action="append", metavar="ID",
                   help="a simulated servo at this ID, one for each --id (default: one at ID 1; "
                        "a servo new from the factory is at ID 0)")
    c.add_argument("--tcp", type=int, nargs="?", const=0, default=None, metavar="PORT",
                   help="a TCP port instead of a pty (any free port if none given)")
    c.add_argument("--link", help="symlink to the pty (not with --tcp)")
    c.add_argument("--host-link", metavar="usb|ftdi[:MS]|raw", help="the host's USB adapter: usb (default), "
                   "ftdi (a 16 ms latency timer, or MS) or raw (docs/simulator.md)")
    c.add_argument("--state", help="folder for the flash files")
    c.add_argument("--plant", help="a plant file: motor, gears, heat (hal/ports/host/plants/*.toml)")
    return ap
