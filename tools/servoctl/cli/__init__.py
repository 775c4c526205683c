"""servoctl's command line (the `servoctl` console script, `python -m
servoctl.cli`): the commands on top of the library (servoctl), with what
only they use: the parser (args.py), each group of commands in its
cmd_*.py with its own table of them (app.py gathers them), rich's console
(console.py, live.py). It needs the extra servoctl[cli] (rich); without it,
main still answers --version and --help (the parser needs no rich) and
otherwise says which extra to install. The library imports nothing from
here (scripts/check_layers.py)."""
import importlib.util
import sys

from .. import extras


def main(argv=None, clock=None) -> int:
    """The console script: servoctl's command line (app.main), once its
    extra is there. clock: app.main's."""
    if importlib.util.find_spec("rich") is None:
        from .args import build_parser

        build_parser().parse_args(argv)  # --version, --help and a bad option end here
        print(f"servoctl: error: {extras.missing_text('rich')}", file=sys.stderr)
        return 2  # UsageError's exit code: the command cannot run as installed
    from .app import main as run

    return run(argv, clock)
