"""servoctl is a library with a command line on top (tools/pyproject.toml,
servoctl/extras.py): the library, what a program and the LeRobot plugins
import, needs pyserial alone; the command line (servoctl.cli) is the extra
servoctl[cli] (rich), the heavy parts are extras too (installing servoctl
into the LeRobot environment once pulled in mujoco, unicorn, cmsis-svd,
matplotlib and scipy, none of which the plugins import). Checked by the
metadata, by every module the plugins can reach (their lazy imports too),
by a Python that sees pyserial and servoctl alone importing every library
module and driving a simulated servo and an arm, and by one that sees the
cli's extra besides running the command line.""" 
import importlib.metadata as metadata
import json
import modulefinder
import shutil
import re
import subprocess
import sys
import tomllib

import pytest

from servoctl.extras import OPTIONAL
from servoctl.sim import Simulator

from ..launchers import REPO

TOOLS = REPO / "tools"
PROJECT = tomllib.loads((TOOLS / "pyproject.toml").read_text())["project"]
PATHS = [TOOLS, REPO / "protocol", REPO / "bootloader"]  # servoctl, servo_schema, servo_image


def name(requirement: str) -> str:
    return re.match(r"[A-Za-z0-9_.-]+", requirement).group(0).lower().replace("_", "-")


def core_modules(requirements=None) -> set:
    """The top-level modules of servoctl's core dependencies (or of these
    requirements) and theirs."""
    seen, todo, modules = set(), [name(r) for r in requirements or PROJECT["dependencies"]], set()
    while todo:
        try:
            dist = metadata.distribution(todo.pop())
        except metadata.PackageNotFoundError:
            continue  # for another Python (a marker): not this one's
        if dist.metadata["Name"].lower() in seen:
            continue
        seen.add(dist.metadata["Name"].lower())
        todo += [name(r) for r in dist.requires or [] if "extra ==" not in r]
        modules |= {f.parts[0].removesuffix(".py") for f in dist.files or ()
                    if not f.parts[0].endswith((".dist-info", ".pth")) and f.parts[0] not in ("..", "__pycache__")}
    return modules


def test_the_library_needs_pyserial_alone_and_the_command_line_rich():
    assert [name(r) for r in PROJECT["dependencies"]] == ["pyserial"]
    assert [name(r) for r in PROJECT["optional-dependencies"]["cli"]] == ["rich"]
    assert PROJECT["scripts"] == {"servoctl": "servoctl.cli:main"}


def test_the_core_leaves_the_heavy_parts_to_extras():
    core = {name(r) for r in PROJECT["dependencies"]}
    extras = {extra: {name(r) for r in reqs} for extra, reqs in PROJECT["optional-dependencies"].items()}
    for module, (distribution, extra, _) in OPTIONAL.items():
        assert distribution not in core, f"{distribution} ({module}) is in servoctl's core"
        assert distribution in extras[extra], f"servoctl[{extra}] does not bring {distribution}"
    everything = {d for reqs in extras.values() for d in reqs if not d.startswith("servoctl")}
    assert extras["all"] == {"servoctl"} and all(e in PROJECT["optional-dependencies"]["all"][0]
                                                 for e in extras if e != "all")
    # scripts/setup.sh installs requirements.txt and `-e tools`: every extra still, as before.
    required = {name(line) for line in (TOOLS / "requirements.txt").read_text().splitlines()
                if line.strip() and not line.startswith("#")}
    assert everything <= required, everything - required


def test_the_plugins_reach_no_module_beyond_the_core():
    """Every import the plugins' code and the servoctl modules they use can
    make, run or not (modulefinder reads the code; LeRobot left out)."""
    finder = modulefinder.ModuleFinder(path=[str(TOOLS / "lerobot_plugins" / p) for p in (
        "lerobot_robot_servoctl", "lerobot_teleoperator_servoctl")] + [str(p) for p in PATHS] + sys.path,
        excludes=["lerobot", *sys.stdlib_module_names, *core_modules()])  # each reached, not read
    finder.import_hook("lerobot_robot_servoctl")
    finder.import_hook("lerobot_teleoperator_servoctl")
    ours = {"lerobot_robot_servoctl", "lerobot_teleoperator_servoctl", "servoctl", "servo_schema", "servo_image",
            "board_facts"}  # servo_image's own, as the firmware's build imports it
    reached = {m.partition(".")[0] for m in [*finder.modules, *finder.badmodules]}
    beyond = reached - ours - set(sys.stdlib_module_names) - {"lerobot", "__main__"}
    assert "servoctl.arm" in finder.modules
    assert beyond <= core_modules(), sorted(beyond - core_modules())


def site_of(tmp_path, modules) -> str:
    """A folder with links to these installed top-level modules alone."""
    site = tmp_path / "site"
    site.mkdir()
    installed = metadata.distribution("pyserial").locate_file("")
    for module in modules:
        for found in (installed / module, installed / f"{module}.py"):
            if found.exists():
                (site / found.name).symlink_to(found)
    return str(site)


def run_alone(tmp_path, script: str, sim, modules):
    """script, run by a Python without its site-packages (-S) that sees
    servoctl's sources and these modules only, given the simulator's URL
    and its control port (argv[2], and SERVOCTL_SIM_CONTROL for the command
    line): its waits for answers are on the simulator's clock, which a
    loaded PC holds back, not the host's. Without a simulator (sim has a
    url alone), the script is given that alone."""
    control = getattr(sim, "control_port", None)
    env = {"PYTHONPATH": ":".join(map(str, [*PATHS, site_of(tmp_path, modules)])),
           "SERVOCTL_STATE_DIR": str(tmp_path / "state")}
    if control is not None:
        env["SERVOCTL_SIM_CONTROL"] = str(control)
    return subprocess.run([sys.executable, "-S", "-c", script, sim.url, *([str(control)] if control else [])],
                          capture_output=True, text=True, timeout=120, env=env)


# The library's modules whose import needs an extra (identify's numpy and scipy).
NEED_AN_EXTRA = {"identify", "identify_fit", "actuator_model", "calibrate"}


def test_the_library_runs_with_pyserial_alone(tmp_path):
    """Every module of the library (servoctl but its cli and ui) imports,
    but those of identify's extra, which say so (a module extras.py names);
    a servo is driven and an unstable drive item refused, and an arm run as
    the follower does; nothing optional is loaded. The console script says
    which extra it needs."""
    library = sorted(p.relative_to(TOOLS).with_suffix("").as_posix().replace("/", ".").removesuffix(".__init__")
                     for p in (TOOLS / "servoctl").rglob("*.py")
                     if not {"cli", "ui", "__pycache__"} & set(p.relative_to(TOOLS / "servoctl").parts))
    assert len(library) > 40 and "servoctl.stream" in library and "servoctl.arm" in library
    script = f"""
import importlib, json, sys
needs = {{}}
for module in {library!r}:
    try:
        importlib.import_module(module)
    except ModuleNotFoundError as e:
        needs[module.removeprefix("servoctl.")] = str(e)  # its own message names the extra
from servoctl import stability
from servoctl.arm import Arm
from servoctl.errors import ValueOutOfRange
from servoctl.protocol import Bus
from servoctl.servo import Servo
from servoctl.stream import RobotLoop
from servoctl.sim import Simulator
with Bus(sys.argv[1], 115200, clock=Simulator.running(int(sys.argv[2])).clock_s) as bus:
    servo = Servo(bus, 1)
    servo.move(450, interval_ms=100)
    bus.sleep(3.0)  # the first move after power-up: its soft start too
    angle = servo.read_motion().angle_decideg
    try:
        servo.write("gain_ki", 1023)
        refused = None
    except ValueOutOfRange as e:
        refused = str(e)
    loop = RobotLoop(bus, [1], 0.02)
    cycled = [sorted(loop.cycle({{1: 45.0}})) for _ in range(5)]
    arm = Arm(bus, {{"a": 1}})
    arm.open()
    arm.send(arm.hold_here())
    arm.positions()
    arm.close()
print(json.dumps({{"needs": needs, "angle": angle, "refused": refused, "cycled": cycled,
                  "optional": sorted(m for m in {sorted(OPTIONAL)} if m in sys.modules)}}))
from servoctl.cli import main
sys.exit(main(["--port", sys.argv[1], "scan"]))
"""
    with Simulator(ids=[1], fast=True) as sim:
        done = run_alone(tmp_path, script, sim, core_modules())
    assert done.stdout, done.stderr
    said = json.loads(done.stdout.splitlines()[-1])
    assert set(said["needs"]) == NEED_AN_EXTRA, said["needs"]
    assert all("pip install 'servoctl[identify]'" in why for why in said["needs"].values()), said["needs"]
    assert abs(said["angle"] - 450) <= 20, said
    assert "gain_ki = 1023 refused, not written" in said["refused"], said
    assert said["cycled"] == [[1]] * 5, said
    assert said["optional"] == [], said
    assert done.returncode == 2, done.stderr
    assert "rich is not installed, servoctl's extra for the command line" in done.stderr, done.stderr
    assert "pip install 'servoctl[cli]'" in done.stderr, done.stderr


def test_the_command_line_runs_with_its_extra(tmp_path):
    """pyserial and servoctl[cli]'s rich (and theirs) alone: the commands
    run, rich's tables included; a command that needs another extra names
    it."""
    script = f"""
import sys
from servoctl.cli import main
for argv in (["scan"], ["info", "1"], ["move", "1", "30"], ["monitor", "1", "--count", "2"]):
    code = main(["--port", sys.argv[1], *argv])
    print("exit", argv[0], code, flush=True)
print(sorted(m for m in {sorted(OPTIONAL)} if m in sys.modules), flush=True)
sys.exit(main(["--port", sys.argv[1], "identify", "1"]))
"""
    with Simulator(ids=[1], fast=True) as sim:
        done = run_alone(tmp_path, script, sim, core_modules(PROJECT["dependencies"] +
                                                              PROJECT["optional-dependencies"]["cli"]))
    lines = done.stdout.splitlines()
    assert [line for line in lines if line.startswith("exit")] == \
        ["exit scan 0", "exit info 0", "exit move 0", "exit monitor 0"], done.stdout + done.stderr
    assert lines[-1] == "['rich']", done.stdout + done.stderr
    assert done.returncode == 2, done.stderr
    assert "scipy is not installed, servoctl's extra for identify, tune and calibrate" in done.stderr or \
        "numpy is not installed, servoctl's extra for identify, tune and calibrate" in done.stderr, done.stderr
    assert "pip install 'servoctl[identify]'" in done.stderr, done.stderr


LEROBOT_PYTHON = REPO / ".venv-lerobot" / "bin" / "python"  # its setuptools builds a wheel offline


@pytest.mark.skipif(not LEROBOT_PYTHON.exists(), reason="no .venv-lerobot (scripts/lerobot_env.sh)")
def test_an_installed_copy_imports_the_arm_without_the_firmware_tree(tmp_path):
    """`pip install tools` (not -e) leaves firmware/boards behind: servo_image
    listed that folder when imported (scan -> update -> image), so
    servoctl.arm raised FileNotFoundError and LeRobot dropped the plugins.
    Installed from a copy of the sources, imported by a Python that sees
    that installation and the core's modules only; a shared ID is still
    told (scan's probe, imported when it is needed)."""
    source = tmp_path / "src"
    for part in ("tools/pyproject.toml", "tools/servoctl", "tools/vboard", "protocol/servo_schema",
                 "bootloader/servo_image"):
        copy = shutil.copytree if (REPO / part).is_dir() else shutil.copy
        (source / part).parent.mkdir(parents=True, exist_ok=True)
        copy(REPO / part, source / part, **({"ignore": shutil.ignore_patterns("__pycache__")}
                                            if (REPO / part).is_dir() else {}))
    site = tmp_path / "site"
    subprocess.run([str(LEROBOT_PYTHON), "-m", "pip", "install", "-q", "--no-deps", "--no-build-isolation",
                    "--no-index", "--target", str(site), str(source / "tools")], check=True, timeout=300,
                   capture_output=True)
    installed = metadata.distribution("pyserial").locate_file("")
    for module in core_modules():
        for found in (installed / module, installed / f"{module}.py"):
            if found.exists() and not (site / found.name).exists():
                (site / found.name).symlink_to(found)
    script = """
import sys
import servoctl.arm
from servoctl.arm import Arm, JointShared
from servoctl.protocol import Bus
from servoctl.sim import Simulator
print(servoctl.arm.__file__)
with Bus(sys.argv[1], 115200, clock=Simulator.running(int(sys.argv[2])).clock_s) as bus:  # the answers' clock
    try:
        Arm(bus, {"a": 1}).positions()
    except JointShared as e:
        print("shared:", e)
"""
    with Simulator(ids=[1, 1], fast=True) as sim:
        done = subprocess.run([sys.executable, "-S", "-c", script, sim.url, str(sim.control_port)],
                              capture_output=True, text=True,
                              timeout=120, cwd=tmp_path, env={"PYTHONPATH": str(site),
                                                              "SERVOCTL_STATE_DIR": str(tmp_path / "state")})
    assert done.returncode == 0, done.stderr
    where, said = done.stdout.splitlines()[:2]
    assert where.startswith(str(site)), where
    assert "TWO OR MORE SERVOS hold this ID" in said, said
