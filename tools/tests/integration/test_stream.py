"""Streamed setpoints on simulated servos: servoctl stream follows a CSV
trajectory on three servos and reports how closely; the robot loop runs a
cycle per call, every servo's state back, at a rate within the wire's;
Stream refuses what it cannot send. Time is the simulator's."""
import math
import re

import pytest

from servoctl import protocol as p
from servoctl.cli import main
from servoctl.errors import UsageError, ValueOutOfRange
from servoctl.servo import Servo
from servoctl.sim import Simulator
from servoctl.stream import Limits, RobotLoop, Stream, read_trajectory

from .conftest import finish, _start

IDS = [1, 2, 3]


@pytest.fixture
def sim3(tmp_path):
    s = _start(tmp_path, IDS)
    yield s
    finish(s, IDS)


def sine_csv(path, ids, seconds=3.0, period_s=0.02, amplitude=60.0, hz=0.5):
    """A 0.5 Hz +-60 deg sine from one of its peaks: from rest, as a
    trajectory a motor can follow from its first row."""
    rows = ["time," + ",".join(map(str, ids))]
    for k in range(int(round(seconds / period_s)) + 1):
        t = k * period_s
        a = amplitude * math.cos(2 * math.pi * hz * t)
        rows.append(f"{t:.3f}," + ",".join(f"{a:.3f}" for _ in ids))
    path.write_text("\n".join(rows) + "\n")
    return path


def test_stream_follows_a_csv_trajectory(sim3, tmp_path, capsys):
    for i in IDS:
        with sim3.bus(timeout=0.2) as bus:
            Servo(bus, i).write("soft_start_on", 0)
    csv = sine_csv(tmp_path / "sine.csv", IDS)
    rc = main(["--port", sim3.url, "stream", str(csv), "--lead-in", "0.5"], clock=sim3.clock_s)
    out = capsys.readouterr().out
    print(out)
    assert rc == 0
    assert "151 setpoints at 50 Hz to 3 servo(s)" in out
    rms = [float(x) for x in re.findall(r"tracking error RMS ([0-9.]+) deg", out)]
    assert len(rms) == 3
    peak = [float(x) for x in re.findall(r"peak ([0-9.]+) deg", out)]
    # The servos follow a 0.5 Hz +-60 deg sine (188 deg/s at its fastest)
    # within 0.8 deg RMS, measured when each state was taken (the
    # simulator's 250 us step blurs that by 0.05 deg). The peak is the
    # host's: under CI's load a late send costs a degree or two (2.3 seen).
    assert all(r < 0.8 for r in rms), out
    assert all(x < 5.0 for x in peak), out
    assert "did not come back" not in out


def test_the_robot_loop_returns_every_state_within_the_wire_limit(tmp_path):
    # servoctl's loop against the wire alone: the raw host link hands each
    # byte over as it ends on the wire. Behind the default USB adapter a
    # cycle also waits up to a 1 ms frame and 4 character times for its
    # answers (docs/simulator.md, "The host's adapter"; the benchmark's figures).
    sim3 = Simulator(ids=IDS, host_link="raw", state_dir=str(tmp_path / "state")).start()
    try:
        rate, loop = robot_loop_rate(sim3)
    finally:
        finish(sim3, IDS)
    assert loop.missed == 0
    assert rate.cycles == 60
    # A cycle cannot beat its own bytes on the wire; at 115 200 baud the
    # wire, not the host, sets the pace (scripts/stream_bench.sh: 0.98).
    assert 0.9 <= rate.ratio <= 1.0
    print(f"robot loop, 3 servos at 115200: {rate.rate_hz:.0f} Hz of {rate.wire_limit_hz:.0f} "
          f"({rate.ratio:.2f} of the wire limit)")


def robot_loop_rate(sim3):
    with sim3.bus(timeout=0.2) as bus:
        loop = RobotLoop(bus, IDS, 0.01)
        for k in range(60):
            states = loop.cycle({i: 5.0 * math.sin(k / 10) for i in IDS})
            assert sorted(states) == IDS
        return loop.rate(), loop


def test_a_stream_starts_several_servos_in_one_frame(sim3):
    with sim3.bus(timeout=0.2) as bus:
        stream = Stream(bus, IDS, 0.02)
        code, content = stream.frame_content({1: 10.0, 2: -10.0, 3: 0.0})
        assert code == p.SYNC and content[:3] == bytes([p.STREAM_SETPOINT, 9, 3])
        for _ in range(10):
            stream.send({1: 10.0, 2: -10.0, 3: 0.0})
            bus.sleep(0.02)
        bus.sleep(0.5)
        angles = {i: Servo(bus, i).monitor().angle_decideg for i in IDS}
    assert abs(angles[1] - 100) <= 2 and abs(angles[2] + 100) <= 2 and abs(angles[3]) <= 2


def test_stream_refuses_what_it_cannot_send():
    class NoBus:
        pass

    with pytest.raises(ValueOutOfRange, match="period must be 1..1000 ms"):
        Stream(NoBus(), [1], 2.0)
    with pytest.raises(UsageError, match="listed more than once"):
        Stream(NoBus(), [1, 1], 0.02)
    s = Stream(NoBus(), [1, 2], 0.02, limits={1: Limits(), 2: Limits()})
    with pytest.raises(UsageError, match="a setpoint for every streamed servo"):
        s.frame_content({1: 0.0})
    with pytest.raises(ValueOutOfRange, match="angle must be"):
        s.frame_content({1: 0.0, 2: 1e6})


@pytest.mark.parametrize("text, why", [
    ("time,1\n0,0\n", "a header and at least two rows"),
    ("time,1\n0,0\n0.02,1\n0.05,2\n", "evenly spaced"),
    ("time,x\n0,0\n0.02,1\n", "servo IDs"),
    ("time,1,2\n0,0,0\n0.02,1\n", "one finite angle per servo"),
])
def test_a_bad_trajectory_file_says_what_is_wrong(tmp_path, text, why):
    path = tmp_path / "t.csv"
    path.write_text(text)
    with pytest.raises(UsageError, match=why):
        read_trajectory(str(path))
