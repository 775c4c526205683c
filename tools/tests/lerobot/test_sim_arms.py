"""tools/lerobot_plugins/sim_arms.py, the two simulated arms of
docs/lerobot.md's walk-through: started a second time it deleted the
running instance's env file on its way out; --state keeps what a
calibration stored on the servos from one start to the next; killed, it
left its simulators running and a stale env file; SIGHUP, a shared
--state and a port in use. The host's clock here only bounds waits."""
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from servoctl import link_rate
from servoctl.servo import Servo
from servoctl.protocol import Bus

from ..launchers import REPO

SIM_ARMS = REPO / "tools" / "lerobot_plugins" / "sim_arms.py"
START_S = 60  # the host's wait for two servo_sim to start: a loaded PC is slow to


def start(env, *extra):
    return subprocess.Popen([sys.executable, str(SIM_ARMS), "--follower", "0", "--leader", "0", "--env", str(env),
                             *map(str, extra)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def until_written(proc, env) -> dict:
    deadline = time.monotonic() + START_S
    while not env.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "sim_arms.py did not write its env file"
        time.sleep(0.1)
    return dict(line.split("=", 1) for line in env.read_text().split())


def stop(proc) -> None:
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


@pytest.fixture
def procs():
    started = []
    yield started
    for p in started:
        stop(p)


def test_a_second_instance_leaves_the_running_ones_env_file_alone(tmp_path, procs):
    env = tmp_path / "sim-arms.env"
    procs.append(first := start(env))
    until_written(first, env)
    written = env.read_text()
    procs.append(second := start(env))
    _, err = second.communicate(timeout=START_S)
    assert second.returncode == 1 and f"runs with {env}" in err, err
    assert env.read_text() == written  # still the running one's
    stop(first)
    assert not env.exists()  # its own, removed on its way out


def test_state_keeps_the_servos_flash_from_one_start_to_the_next(tmp_path, procs):
    env, state = tmp_path / "sim-arms.env", tmp_path / "state"
    for run in range(2):
        procs.append(proc := start(env, "--state", state))
        ports = until_written(proc, env)
        link_rate.open_rate(ports["FOLLOWER_PORT"], 1000000, ports["FOLLOWER_CONTROL"])
        with Bus(ports["FOLLOWER_PORT"], 1000000, timeout=0.2) as bus:
            if run == 0:
                assert Servo(bus, 1).read("angle_max") == 1200  # a calibration's range: not asked for one
                Servo(bus, 1).write("angle_max", 600)  # as a calibration stores a range
            assert Servo(bus, 1).read("angle_max") == 600
        stop(proc)
    assert (state / "follower").is_dir() and (state / "leader").is_dir()


def children(pid: int) -> list:
    return [int(c) for t in Path(f"/proc/{pid}/task").iterdir() for c in (t / "children").read_text().split()]


@pytest.fixture
def orphans():
    """servo_sim processes a test found: any still running at its end are
    stopped (a sim_arms.py that failed to take them with it)."""
    found = []
    yield found
    for pid in found:
        if not gone(pid):
            os.kill(pid, signal.SIGKILL)


def gone(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0] == "Z"  # a zombie: ended
    except FileNotFoundError:
        return True


def test_killed_its_simulators_end_and_its_env_file_is_taken_as_stale(tmp_path, procs, orphans):
    """kill -9 (or a closed terminal's SIGHUP) left both servo_sim running
    and the env file behind; --nudge then failed with a traceback."""
    env = tmp_path / "sim-arms.env"
    procs.append(first := start(env))
    until_written(first, env)
    orphans += (sims := children(first.pid))
    assert len(sims) == 2, sims
    first.kill()
    first.wait()
    deadline = time.monotonic() + START_S  # a hang's guard, not a measure
    while not all(gone(p) for p in sims):
        assert time.monotonic() < deadline, f"servo_sim {sims} still run after sim_arms.py was killed"
        time.sleep(0.1)
    nudged = subprocess.run([sys.executable, str(SIM_ARMS), "--env", str(env), "--nudge", "1"],
                            capture_output=True, text=True, timeout=START_S)
    assert nudged.returncode == 1 and "Traceback" not in nudged.stderr, nudged.stderr
    assert f"no sim_arms.py runs with {env} (a stale file" in nudged.stderr, nudged.stderr
    procs.append(again := start(env))
    while until_written(again, env)["SIM_ARMS_PID"] != str(again.pid):  # the stale file taken, rewritten
        assert time.monotonic() < deadline + START_S, "the stale env file was not taken"
        time.sleep(0.1)


def test_sighup_stops_both_and_removes_the_env_file(tmp_path, procs, orphans):
    env = tmp_path / "sim-arms.env"
    procs.append(proc := start(env))
    until_written(proc, env)
    orphans += (sims := children(proc.pid))
    proc.send_signal(signal.SIGHUP)
    proc.wait(timeout=START_S)
    assert proc.returncode == 0 and not env.exists()
    assert all(gone(p) for p in sims)


def test_a_second_instance_on_the_same_state_is_refused(tmp_path, procs):
    state = tmp_path / "state"
    procs.append(first := start(tmp_path / "a.env", "--state", state))
    until_written(first, tmp_path / "a.env")
    procs.append(second := start(tmp_path / "b.env", "--state", state))
    _, err = second.communicate(timeout=START_S)
    assert second.returncode == 1 and f"runs with --state {state}" in err, err
    assert not (tmp_path / "b.env").exists()


def test_a_port_in_use_is_said_without_a_traceback(tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        done = subprocess.run([sys.executable, str(SIM_ARMS), "--follower", str(port), "--leader", "0", "--env",
                               str(tmp_path / "sim-arms.env")], capture_output=True, text=True, timeout=START_S)
    assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
    assert "Address already in use" in done.stderr and "free ones" in done.stderr, done.stderr
