"""tools/lerobot_plugins/sim_arms.py, the two simulated arms of
docs/lerobot.md's walk-through: started a second time it deleted the
running instance's env file on its way out; --state keeps what a
calibration stored on the servos from one start to the next."""
import signal
import subprocess
import sys
import time

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
