"""A stream on the host's timeline (docs/streaming.md, "On the host's
timeline"): servoctl stream on a paced simulator, its rows sent as a real
host sends them (servoctl.host_timing: +-10 ms, one row in twenty a whole
period late with the next), follows the file within 0.3 deg RMS. The
servo plays each setpoint at its stamp's place, not when it arrives.
Time is the simulator's."""
import math
import re

import pytest

from servoctl.cli import main
from servoctl.host_timing import HostTiming
from servoctl.servo import Servo
from servoctl.sim import Simulator

from .conftest import finish
from .test_stream import sine_csv

IDS = [1, 2, 3]


@pytest.fixture
def paced3(tmp_path):
    s = Simulator(ids=IDS, state_dir=str(tmp_path / "paced"), paced=True).start()
    yield s
    finish(s, IDS)


def streamed_rms(sim, csv, capsys, *host) -> list:
    rc = main(["--port", sim.url, "stream", str(csv), "--lead-in", "0.5", *host], clock=sim.clock_s)
    out = capsys.readouterr().out
    assert rc == 0, out
    rms = [float(x) for x in re.findall(r"tracking error RMS ([0-9.]+) deg", out)]
    assert len(rms) == len(IDS) and all(map(math.isfinite, rms)), out
    return rms


def test_a_late_or_early_host_changes_nothing_of_the_stream(paced3, tmp_path, capsys):
    """Before, each frame's lateness was a position error the next cubic
    corrected: 1.09 deg RMS and 7 543 deg/s^2 on a real-time simulator.
    Within the 0.3 deg streaming.md gives; what the jitter still costs is the servo's
    estimate of the host's clock, which starts from the first frame (up to
    10 ms off) and moves 1/8 ms a frame."""
    with paced3.bus(timeout=0.2) as bus:
        for i in IDS:
            Servo(bus, i).write("soft_start_on", 0)
    csv = sine_csv(tmp_path / "sine.csv", IDS)
    on_time = streamed_rms(paced3, csv, capsys)
    jittered = streamed_rms(paced3, csv, capsys, "--host-jitter-ms", "10", "--host-late-every", "20")
    print(f"RMS on time {on_time}, with +-10 ms and 1 in 20 a period late {jittered}")  # the docs' figures
    assert all(r <= 0.15 for r in on_time), on_time
    assert all(r <= 0.3 for r in jittered), jittered


def test_the_host_timing_model():
    on_time = HostTiming()
    assert not on_time and on_time.leaves(3, 1.0, 0.02) == 1.0
    host = HostTiming(0.01, 20)
    moved = [host.leaves(k, k * 0.02, 0.02) - k * 0.02 for k in range(200)]
    late = [moved[k] for k in range(19, 200, 20)]
    assert all(m == pytest.approx(0.02) for m in late)  # a whole period late
    rest = [m for k, m in enumerate(moved) if k % 20 not in (19, 0)]
    assert max(rest) <= 0.01 + 1e-12 and min(rest) >= -0.01 - 1e-12 and max(rest) - min(rest) > 0.015
    for bad in ((-0.001, 0), (1e6, 0), (float("nan"), 0), (0.01, -1)):
        with pytest.raises(ValueError):
            HostTiming(*bad)
