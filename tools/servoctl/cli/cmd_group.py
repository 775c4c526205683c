"""servoctl's commands on several servos at once: sync-move, broadcast-move,
async, and the whole bus's settings to a file and back (backup, restore)."""
import sys

from . import args as args_
from .. import group, link_rate, outcome, scan
from .. import protocol as p
from ..errors import NoReply
from ..servo import Servo


def cmd_sync_move(bus, args):
    targets = args_.distinct_targets(args.targets)
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
    """With --with-link the host follows the servos' rates: during the
    restore, and after it to the rate they were moved to."""
    done, moved = group.restore(bus, args.file, args.with_link,
                                lambda rate: link_rate.set_rate(bus, args.sim_control, rate))
    print(f"restored {len(done)} servo(s) ({', '.join(map(str, done))}) from {args.file}")
    rates = set(moved.values())
    if len(rates) > 1:
        print(f"servoctl: warning: the servos now speak different rates "
              f"({', '.join(f'servo {i}: {r}' for i, r in moved.items())}): one bus runs at one rate",
              file=sys.stderr)
    elif rates:
        who = "servo" if len(moved) == 1 else "servos"
        print(link_rate.after_change(bus, f"{who} {', '.join(map(str, moved))}", rates.pop(), args.sim_control))
    return 0


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "sync-move": cmd_sync_move,
    "broadcast-move": cmd_broadcast_move,
    "async": cmd_async,
    "backup": cmd_backup,
    "restore": cmd_restore,
}
