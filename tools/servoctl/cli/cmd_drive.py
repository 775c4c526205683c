"""servoctl's commands on the drive train (identify, calibrate, tune): scipy
is loaded for these commands alone. calibrate and tune write stored items
along the way: a SIGTERM or SIGHUP puts them back as Ctrl-C does."""
from ..drive_guard import check_horn_free
from ..putback import signals_interrupt
from ..servo import Servo


def cmd_identify(bus, args):
    from .drive_report import cmd_identify as identify  # scipy: loaded for this command alone

    check_horn_free(Servo(bus, args.id), "identify", args.past_limits)
    return identify(bus, args)


def cmd_calibrate(bus, args):
    from .drive_report import cmd_calibrate as calibrate  # scipy (identify's come_to_rest): this command alone

    check_horn_free(Servo(bus, args.id), "calibrate", args.past_limits)
    with signals_interrupt():
        return calibrate(bus, args)


def cmd_tune(bus, args):
    from .drive_report import cmd_tune as tune  # scipy (identify): loaded for this command alone

    check_horn_free(Servo(bus, args.id), "tune", args.past_limits)
    with signals_interrupt():
        return tune(bus, args)


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "identify": cmd_identify,
    "tune": cmd_tune,
    "calibrate": cmd_calibrate,
}
