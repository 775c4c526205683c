"""Ctrl-C ends every long-running command with exit 130, as the exit-code
table (docs/servoctl.md) says: a monitor and `servoctl sim` ended with 0
(a monitor's plot is still saved, a simulator still stopped cleanly). Each
command runs as a user's would, in its own process, sent SIGINT once it
is under way. The tests themselves run with SIGINT ignored, as a shell
starts a background job (a CI run, `stress.sh &`): the command is started
as from a user's terminal all the same (launchers.servoctl_child)."""
import signal
import subprocess
import time

import pytest

from servoctl.sim import Simulator

from ..launchers import servoctl_child


@pytest.fixture(autouse=True)
def run_in_the_background():
    """SIGINT ignored in this process while the test runs, as in a
    background job: what its children inherit unless told otherwise."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    yield
    signal.signal(signal.SIGINT, previous)


def _interrupted(argv, started) -> tuple:
    """servoctl argv in a process, SIGINT once it has printed a line holding
    started (its stdout or stderr), or once started() is true (a command
    that prints nothing until it ends: judged by what it did, not by how
    long a loaded PC took to start it); (exit code, what it printed)."""
    proc = servoctl_child(*argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        seen = []
        deadline = time.monotonic() + 60
        if callable(started):
            while not started() and proc.poll() is None and time.monotonic() < deadline:
                time.sleep(0.05)
            proc.send_signal(signal.SIGINT)
            started = None
        while started and time.monotonic() < deadline:
            line = proc.stdout.readline()
            if not line:
                break
            seen.append(line)
            if started in line:
                proc.send_signal(signal.SIGINT)
                break
        out, _ = proc.communicate(timeout=30)
        return proc.returncode, "".join(seen) + out
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()


@pytest.fixture
def sim(tmp_path):
    with Simulator(ids=[1], state_dir=str(tmp_path / "state")) as sim:
        yield sim


def _moving(sim):
    return lambda: abs(sim.state(1)["angle"]) > 1.0  # record's 20 s move is under way


@pytest.mark.parametrize("argv, started", [
    (["monitor", "1", "--json"], '"id": 1'),
    (["scan", "--last", "253"], "servo 1 at"),
    (["record", "1", "90", "--interval", "20000", "--out", "{tmp}/rec"], _moving),
])
def test_a_command_on_the_bus_interrupted_exits_130(sim, tmp_path, argv, started):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    # --sim-control: servoctl's waits (scan's reply window) are on the
    # simulator's clock, so a loaded PC does not make servo 1 miss its slot.
    rc, out = _interrupted(["--port", sim.url, "--sim-control", str(sim.control_port), *argv],
                           started(sim) if started is _moving else started)
    assert rc == 130 and "servoctl: interrupted" in out, (rc, out)


def test_the_simulator_interrupted_exits_130_and_stops(tmp_path):
    rc, out = _interrupted(["sim", "--tcp", "0", "--state", str(tmp_path / "state")], "simulator running")
    assert rc == 130 and "simulator stopped" in out and "servoctl: interrupted" in out, (rc, out)
