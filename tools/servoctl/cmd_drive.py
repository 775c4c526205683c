"""servoctl's commands on the drive train (identify, calibrate, tune): scipy
is loaded for these commands alone."""


def cmd_identify(bus, args):
    from .identify_report import cmd_identify as identify  # scipy: loaded for this command alone

    return identify(bus, args)


def cmd_calibrate(bus, args):
    from .calibrate import cmd_calibrate as calibrate  # scipy (identify's come_to_rest): this command alone

    return calibrate(bus, args)


def cmd_tune(bus, args):
    from .tune import cmd_tune as tune  # scipy (identify): loaded for this command alone

    return tune(bus, args)
