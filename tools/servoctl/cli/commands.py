"""servoctl's commands on a bus by name, each command module's own table
of them gathered (COMMANDS), and run_command, which runs one: for the
command line (app.py, which adds ui) and for the page servoctl ui serves
(ui/worker.py), which may run every one of these."""
import sys

from .. import link_rate, scan
from ..errors import BadAnswer, NoReply
from . import (cmd_bus, cmd_config, cmd_drive, cmd_faults, cmd_group, cmd_info, cmd_monitor, cmd_motion,
               cmd_record, cmd_stream, cmd_update)

_MODULES = (cmd_bus, cmd_info, cmd_faults, cmd_config, cmd_motion, cmd_monitor, cmd_record, cmd_stream,
            cmd_drive, cmd_group, cmd_update)
COMMANDS = {name: run for module in _MODULES for name, run in module.COMMANDS.items()}
# The optional modules each command needs whatever its options (extras.py),
# from the modules that say: app.py checks them before it opens the port.
EXTRAS = {name: needs for module in _MODULES for name, needs in getattr(module, "EXTRAS", {}).items()}


def run_command(bus, args, table=None) -> int:
    """One parsed command on an open bus, from table (COMMANDS if None;
    servoctl ui runs its page's requests here too): a silent servo's
    NoReply says why it may be."""
    try:
        return (table or COMMANDS)[args.command](bus, args)
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
