"""The maker's LeRobot plugin (lerobot-robot-viola with lerobot-motor-starai,
their real code from PyPI) drives a simulated 7-servo arm, IDs 0-6 at
1 Mbaud, as a user's script would: connect (a PortHandler.ping of each
motor), read the observation, send an action, read it back.

LeRobot pulls in torch, so the plugin lives in its own environment,
.venv-lerobot, which the test command makes once (scripts/lerobot_env.sh);
the plugin runs there, in a child process, against servo_sim's pty."""
import json
import subprocess
from pathlib import Path

import pytest

from servoctl.servo import Servo
from servoctl.sim import Simulator

from ..integration.conftest import finish
from ..launchers import REPO

PYTHON = REPO / ".venv-lerobot" / "bin" / "python"
DRIVER = Path(__file__).with_name("drive_arm.py")
IDS = list(range(7))
BAUD_1M = 8  # item 36's index for 1 000 000 baud


@pytest.mark.wall_clock  # the maker's SDK underneath times on host time
@pytest.mark.skipif(not PYTHON.exists(), reason="no .venv-lerobot: the test command makes it "
                    "(scripts/lerobot_env.sh; LEROBOT_ENV=0 had it skipped)")
def test_the_makers_lerobot_plugin_drives_a_simulated_arm(tmp_path):
    # The SDK under the plugin waits on the wall clock (100 ms an answer):
    # the simulator gets a real-time twin's priority where it may (root).
    sim = Simulator(ids=IDS, tcp=False, state_dir=str(tmp_path / "state"), nice=-10).start()
    try:
        with sim.bus(timeout=0.2) as bus:
            for i in IDS:
                Servo(bus, i).write("soft_start_on", 0)
                Servo(bus, i).write("baud", BAUD_1M)  # answered at 115200, then it switches
        done = subprocess.run([str(PYTHON), str(DRIVER), sim.url, str(tmp_path / "calibration")],
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr[-3000:]
        seen = json.loads(done.stdout.strip().splitlines()[-1])
        sim.sleep(0.5)  # the plugin's moves (350 ms) are over on the simulated clock
        angles = {i: sim.state(i)["angle"] for i in IDS}
        bauds = {sim.state(i)["baud"] for i in IDS}
    finally:
        finish(sim, IDS)
    assert bauds == {1000000}
    assert seen["ids"] == {**{f"Motor_{k}": k for k in range(6)}, "gripper": 6}
    assert set(seen["before"].values()) == {2048, 50.0}  # counts at 0 deg; the gripper mid-range
    for name, motor_id in seen["ids"].items():
        assert angles[motor_id] == pytest.approx(seen["targets_deg"][name], abs=0.5), (name, angles)
    for name, deg in seen["after_deg"].items():  # what the plugin read back
        assert deg == pytest.approx(seen["targets_deg"][name], abs=0.5), (name, seen)
