"""servoctl's command line registers each command once, explicitly: each
cmd_*.py module's own table (COMMANDS, or NO_BUS for those that start what
they need) names functions defined in that module, no name is in two
tables, and the parser's commands are the tables' names, all and only."""
import argparse
import pkgutil
from importlib import import_module

from servoctl import cli
from servoctl.cli import app, commands
from servoctl.cli.args import build_parser


def tables():
    """{module name: its tables} for every cmd_*.py module of servoctl.cli."""
    found = {}
    for info in pkgutil.iter_modules(cli.__path__):
        if info.name.startswith("cmd_"):
            module = import_module(f"servoctl.cli.{info.name}")
            found[info.name] = [getattr(module, t) for t in ("COMMANDS", "NO_BUS") if hasattr(module, t)]
            assert found[info.name], f"{info.name} registers no command"
            for table in found[info.name]:
                for name, run in table.items():
                    assert run.__module__ == module.__name__, (name, run.__module__)
    return found


def test_each_command_is_registered_once_by_its_module():
    names = [name for module in tables().values() for table in module for name in table]
    assert len(names) == len(set(names)), sorted(n for n in names if names.count(n) > 1)
    assert set(names) == set(app.COMMANDS) | set(app.NO_BUS)
    assert not set(app.COMMANDS) & set(app.NO_BUS)
    assert set(app.COMMANDS) - set(commands.COMMANDS) == {"ui"}  # the page runs the rest


def test_the_parser_has_the_registered_commands():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    assert set(sub.choices) == set(app.COMMANDS) | set(app.NO_BUS)
