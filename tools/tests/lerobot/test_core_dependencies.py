"""servoctl's heavy parts are pip extras (tools/pyproject.toml,
servoctl/extras.py): installing servoctl into the LeRobot environment
pulled in mujoco, unicorn, cmsis-svd, matplotlib and scipy, none of which
the plugins import. Checked three ways: the metadata, every module the
plugins can reach (their lazy imports too), and an arm driven by a Python
that sees servoctl's core dependencies and nothing else."""
import importlib.metadata as metadata
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


def core_modules() -> set:
    """The top-level modules of servoctl's core dependencies and theirs."""
    seen, todo, modules = set(), [name(r) for r in PROJECT["dependencies"]], set()
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


def test_an_arm_runs_with_the_core_alone(tmp_path):
    """A Python without its site-packages (-S) and with only the core's
    modules on its path drives an arm as the follower does; a command
    that needs an extra names it."""
    site = tmp_path / "site"
    site.mkdir()
    installed = metadata.distribution("pyserial").locate_file("")
    for module in core_modules():
        for found in (installed / module, installed / f"{module}.py"):
            if found.exists():
                (site / found.name).symlink_to(found)
    script = f"""
import sys
from servoctl.arm import Arm
from servoctl.protocol import Bus
from servoctl.cli import main
with Bus(sys.argv[1], 115200) as bus:
    arm = Arm(bus, {{"a": 1}})
    arm.open()
    arm.send(arm.hold_here())
    arm.positions()
    arm.close()
print(sorted(m for m in {sorted(OPTIONAL)} if m in sys.modules))
sys.exit(main(["--port", sys.argv[1], "identify", "1"]))
"""
    with Simulator(ids=[1], fast=True) as sim:
        done = subprocess.run([sys.executable, "-S", "-c", script, sim.url], capture_output=True, text=True,
                              timeout=120, env={"PYTHONPATH": ":".join(map(str, [*PATHS, site])),
                                                "SERVOCTL_STATE_DIR": str(tmp_path / "state")})
    assert done.stdout.strip() == "[]", done.stdout + done.stderr
    assert done.returncode == 2, done.stderr
    assert "scipy is not installed (servoctl's extra for identify, tune and calibrate" in done.stderr, done.stderr
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
print(servoctl.arm.__file__)
with Bus(sys.argv[1], 115200) as bus:
    try:
        Arm(bus, {"a": 1}).positions()
    except JointShared as e:
        print("shared:", e)
"""
    with Simulator(ids=[1, 1], fast=True) as sim:
        done = subprocess.run([sys.executable, "-S", "-c", script, sim.url], capture_output=True, text=True,
                              timeout=120, cwd=tmp_path, env={"PYTHONPATH": str(site),
                                                              "SERVOCTL_STATE_DIR": str(tmp_path / "state")})
    assert done.returncode == 0, done.stderr
    where, said = done.stdout.splitlines()[:2]
    assert where.startswith(str(site)), where
    assert "TWO OR MORE SERVOS hold this ID" in said, said
