"""servoctl's commands on firmware images: update (into servos over the
bus) and image (made from an application binary)."""
import sys
import time

from . import args as args_
from ..errors import ServoError


def _version(v) -> str:
    return "none" if v is None else f"0x{v:04x}"


def cmd_update(bus, args):
    from rich.progress import BarColumn, DownloadColumn, TextColumn, TimeRemainingColumn

    from .. import image as img
    from .. import update as upd
    from .console import progress as Progress

    ids, image_file = args_.update_operands(args.targets)
    image = img.load(image_file)
    failed = []
    say = getattr(args, "on_progress", lambda servo_id, done, total: None)  # servoctl ui's bar
    for servo_id in ids:
        columns = [TextColumn(f"servo {servo_id}"), BarColumn(), DownloadColumn(), TimeRemainingColumn()]
        try:
            if args.catch:  # one that does not appear is a failure, and the next is tried
                print(f"servo {servo_id}: power it up now (waiting {args.catch:g} s for its bootloader)",
                      file=sys.stderr)
                upd.catch(bus, servo_id, args.catch)
            started = time.monotonic()
            with Progress(*columns, transient=True, disable=not sys.stderr.isatty()) as progress:
                task = progress.add_task("update", total=len(image.data))
                before, after = upd.update(bus, servo_id, image,
                                           lambda done, total: (progress.update(task, completed=done,
                                                                                total=total),
                                                                say(servo_id, done, total)))
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
    from .. import image as img

    data = img.make(args.binary, args.version, args.board, args.output)
    header = img.parse(data)
    print(f"{args.output}: {len(data)} B, version 0x{header.version:04x}, board 0x{header.board:04x}")
    return 0


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "update": cmd_update,
}

# This module's commands without a bus: they start their own (cli/app.py).
NO_BUS = {
    "image": cmd_image,
}
