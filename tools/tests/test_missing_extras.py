"""A command that needs an optional part (servoctl.extras) says which extra
to install, one line and exit 2, before it sends anything: record does not
move the servo and then fail at its plot, monitor does not sample a run for
a plot file it cannot draw, identify --mujoco does not run its experiment
for a model it cannot make; faults --elf and sim --board say so instead of
a SystemExit or a child's traceback. --version needs no rich."""
import importlib.util

from servoctl import extras
from servoctl.cli import main
from servoctl.servo import Servo
from servoctl.protocol import Bus
from servoctl.sim import Simulator

from .lerobot.test_core_dependencies import PROJECT, core_modules, run_alone


def test_the_command_line_without_an_extra_refuses_before_sending(tmp_path):
    script = f"""
import sys
from servoctl.cli import main
from servoctl.protocol import Bus
from servoctl.servo import Servo

def angle():
    with Bus(sys.argv[1], 115200) as bus:
        return Servo(bus, 1).read_motion().angle_decideg

before = angle()
for argv in (["record", "1", "-45", "--out", "{tmp_path / 'rec'}"],
             ["monitor", "1", "--count", "2", "--plot-file", "{tmp_path / 'run.png'}"],
             ["faults", "1", "--elf", "{tmp_path / 'app.elf'}"]):
    print("exit", argv[0], main(["--port", sys.argv[1], *argv]), flush=True)
# A port that does not open: the missing extra is named all the same (not exit 4).
print("exit record-no-port", main(["--port", "socket://127.0.0.1:9", "record", "1", "-45",
                                   "--out", "{tmp_path / 'rec'}"]), flush=True)
print("exit sim", main(["sim", "--board", "stm32f030k6"]), flush=True)
print("moved", abs(angle() - before) > 20)
"""
    with Simulator(ids=[1], fast=True) as sim:
        done = run_alone(tmp_path, script, sim, core_modules(PROJECT["dependencies"] +
                                                              PROJECT["optional-dependencies"]["cli"]))
    assert done.stdout.splitlines() == ["exit record 2", "exit monitor 2", "exit faults 2", "exit record-no-port 2",
                                        "exit sim 2", "moved False"], done.stdout + done.stderr
    lines = done.stderr.splitlines()
    assert [line.partition(" is not installed")[0] for line in lines] == [
        "servoctl: error: matplotlib", "servoctl: error: matplotlib", "servoctl: error: pyelftools",
        "servoctl: error: matplotlib", "servoctl: error: unicorn"], done.stderr
    assert all("pip install 'servoctl[" in line for line in lines), done.stderr
    assert not (tmp_path / "rec.csv").exists()


def test_the_version_and_help_need_no_rich(tmp_path):
    """pyserial alone: --version and --help answer; a command says which extra, one line."""
    script = "import sys; from servoctl.cli import main; sys.exit(main(sys.argv[1].split()))"

    def run(argv):
        (tmp_path / argv.split()[-1].strip("-")).mkdir()

        class Line:
            url = argv  # run_alone's argument to the script
        return run_alone(tmp_path / argv.split()[-1].strip("-"), script, Line, core_modules())

    version, helped, scan = run("--version"), run("--help"), run("--port socket://127.0.0.1:9 scan")
    assert version.returncode == 0 and version.stdout.startswith("servoctl 0."), version.stdout + version.stderr
    assert helped.returncode == 0 and "Exit codes" in helped.stdout, helped.stderr
    assert scan.returncode == 2 and scan.stderr.count("\n") == 1, scan.stderr
    assert scan.stderr.endswith("pip install 'servoctl[cli]' (in a clone: pip install -e './tools[cli]')\n")


def test_identify_for_a_model_refuses_before_its_experiment(tmp_path, monkeypatch, capsys):
    found = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "mujoco" else found(name, *a))
    with Simulator(ids=[1], fast=True) as sim:
        with Bus(sim.url, 115200) as bus:
            before = Servo(bus, 1).read_motion().angle_decideg
        code = main(["--port", sim.url, "identify", "1", "--mujoco", str(tmp_path / "model.xml")])
        with Bus(sim.url, 115200) as bus:
            after = Servo(bus, 1).read_motion().angle_decideg
    assert code == 2
    assert capsys.readouterr().err == f"servoctl: error: {extras.missing_text('mujoco')}\n"
    assert abs(after - before) <= 20 and not (tmp_path / "model.xml").exists()
