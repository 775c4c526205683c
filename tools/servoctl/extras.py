"""servoctl's optional parts, tools/pyproject.toml's extras: what the
library (pyserial alone: the bus, servos, units, config files, the loop
and the stream, the arm the LeRobot plugins drive) leaves out, which
module each needs and the extra that brings it. The command line is one
(servoctl[cli]: rich). scripts/setup.sh installs them all
(tools/requirements.txt). A module that needs one raises a
ModuleNotFoundError saying which (missing()); a command checks the ones
it needs before it sends anything (require())."""
import importlib.util

# {module: (its distribution, the extra that installs it, what needs it)}
OPTIONAL = {
    "rich": ("rich", "cli", "the command line (the servoctl command)"),
    "numpy": ("numpy", "identify", "identify, tune and calibrate (the drive train's fits)"),
    "scipy": ("scipy", "identify", "identify, tune and calibrate (the drive train's fits)"),
    "mujoco": ("mujoco", "mujoco", "identify --mujoco (the actuator model)"),
    "unicorn": ("unicorn", "vboard", "the virtual boards (sim --board)"),
    "cmsis_svd": ("cmsis-svd", "vboard", "the virtual boards (sim --board)"),
    "matplotlib": ("matplotlib", "plot", "record's and monitor's plots"),
    "aiohttp": ("aiohttp", "ui", "the bench in a browser (ui)"),
    "elftools": ("pyelftools", "elf", "faults --elf (a fault's code named by its function)"),
}


def missing_text(name: str):
    """The line for an optional module that is not installed (a
    ModuleNotFoundError's name), or None if it is not one of them."""
    found = OPTIONAL.get((name or "").partition(".")[0])
    if found is None:
        return None
    distribution, extra, needs = found
    # Where servoctl is installed pip takes the extra from it (servoctl is not on PyPI).
    return (f"{distribution} is not installed, servoctl's extra for {needs}: pip install 'servoctl[{extra}]' "
            f"(in a clone: pip install -e './tools[{extra}]')")


def missing(error: ModuleNotFoundError) -> ModuleNotFoundError:
    """The error an optional module's import raised, saying which extra
    brings it (missing_text) where it is one; to raise from None."""
    text = missing_text(error.name)
    return ModuleNotFoundError(text, name=error.name) if text else error


def require(*modules) -> None:
    """Raises missing()'s error for the first of these optional modules
    that is not installed: what a command checks before it sends anything."""
    for module in modules:
        if importlib.util.find_spec(module) is None:
            raise ModuleNotFoundError(missing_text(module) or f"No module named {module!r}", name=module)
