"""The stream's safety checks on both virtual boards (the F103 and F030
images as flashed), as on servo_sim (tests/integration/test_stream_safety.py):
a row beyond the angle limits and a row that is not a number are refused
with their line before anything moves; after a power cycle at -30 deg, with
the factory's 3 s soft start and a 100 ms bus watchdog, the stream waits for
its lead-in and the joint stays in its turn; a host late or early by the
host-timing model's jitter changes nothing. Time is the boards' simulated
time."""
import math
import re

import pytest

from servoctl.cli import main
from servoctl.servo import Servo
from servoctl.sim import Simulator

from ..integration.test_stream import sine_csv
from ..store_pages import bus_to_baud
from ..stream_report import lead_in_of

BOARDS = ["stm32f103", "stm32f030k6", "stm32g031k8"]



def write_csv(path, rows, period_s=0.02):
    lines = ["time,1"] + [f"{k * period_s:.3f},{a}" for k, a in enumerate(rows)]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("board", BOARDS)
def test_the_stream_repros_on_the_real_images(tmp_path, board, capsys):
    # Paced: the board runs only while the host waits on it, so where the
    # joint is when the stream ends is the stream's, not a loaded PC's
    # (the host late between rows on a board that follows the wall clock
    # left it 4.6 deg short of the last row beside 8 spinners).
    sim = Simulator(ids=[1], state_dir=str(tmp_path / "state"), board=board, paced=True).start()
    try:
        def stream(path, lead_in=0.5):
            # --report-only: safety and the lead-in are judged here; the verdict on
            # the tracking would judge the host's pace on a loaded PC too.
            return main(["--port", sim.url, "stream", str(path), "--lead-in", str(lead_in), "--report-only"],
                        clock=sim.clock_s)

        good = [f"{5 + k * 0.1:.3f}" for k in range(60)]
        for bad, line in (("300", "line 62: servo 1 limits its angle"), ("x", "line 62: 'x' is not a number")):
            rc = stream(write_csv(tmp_path / "bad.csv", good + [bad, "11"]))
            err = capsys.readouterr().err
            assert rc == 2 and line in err, err
        sim.sleep(0.3)
        assert abs(sim.state(1)["angle"]) < 0.5  # nothing moved

        with sim.bus(timeout=0.3) as bus:
            s = Servo(bus, 1)
            assert s.read("soft_start_on") == 1
            s.move(-300, interval_ms=500)
            sim.sleep(3.8)  # the first move after power-up: the soft start's 3 s
        sim.control("powercycle 1")
        sim.sleep(0.6)
        with sim.bus(timeout=0.3) as bus:
            s = Servo(bus, 1)
            assert s.multi_turn_angle()[0] == pytest.approx(-300, abs=3)  # not 330 deg
            s.write("watchdog_ms", 100)
        rows = [f"{-30 + 20 * math.sin(k / 10):.3f}" for k in range(60)]
        rc = stream(write_csv(tmp_path / "t.csv", rows))
        out = capsys.readouterr().out
        print(out)
        assert rc == 0
        assert "soft start" in out and lead_in_of(out) == pytest.approx((-30.0, -30.0), abs=0.15), out
        sim.sleep(0.02)  # the last row reached a period after it was sent, inside the 100 ms watchdog
        print(f"{board}: {sim.state(1)['angle'] - float(rows[-1]):+.3f} deg from the last row a period after it")
        assert abs(sim.state(1)["angle"] - float(rows[-1])) < 2.0
    finally:
        sim.stop()


# The most RMS each board may follow the sine with, on a raw link (the
# F103 measured 0.07 and 0.18, the F030 0.07 and 0.25).
MOST_RMS = {"stm32f103": 0.3, "stm32f030k6": 0.3}


@pytest.mark.parametrize("board,baud", [("stm32f103", 1000000), ("stm32f030k6", 115200)])
def test_a_late_or_early_host_on_the_real_images(tmp_path, board, baud, capsys):
    """The stream on the host's timeline (docs/streaming.md) on the flashed
    images, the boards paced: they run only while the host waits, so the
    host-timing model (+-10 ms, one row in twenty a whole period late with
    the next) is the only jitter there is. A 0.5 Hz +-60 deg sine at 50 Hz
    follows the file within MOST_RMS either way (the F103 at 1 Mbaud; the
    F030 at 115 200, where its ring holds an erase's bytes). The host's link
    is raw, bytes as they end on the wire: behind the USB adapter's model
    (1 ms frames) servoctl stamps a state at the frame that brought it, up
    to 1.35 ms after the servo took it, and the score swung 0.10-0.33 deg
    with a sub-millisecond shift of the servo's start (docs/streaming.md)."""
    sim = Simulator(ids=[1], state_dir=str(tmp_path / "state"), board=board, paced=True,
                    host_link="raw").start()
    try:
        if baud != 115200:
            bus_to_baud(sim, [1], baud, timeout=0.3)
        with sim.bus(baud=baud, timeout=0.3) as bus:
            Servo(bus, 1).write("soft_start_on", 0)
        csv = sine_csv(tmp_path / "sine.csv", [1])
        rms = []
        for host in ([], ["--host-jitter-ms", "10", "--host-late-every", "20"]):
            rc = main(["--port", sim.url, "--baud", str(baud), "--sim-control", str(sim.control_port),
                       "stream", str(csv), "--lead-in", "0.5", *host], clock=sim.clock_s)
            out, err = capsys.readouterr()
            assert rc == 0, out + err
            rms += [float(x) for x in re.findall(r"tracking error RMS ([0-9.]+) deg", out)]
        print(f"{board} at {baud}: RMS on time, with +-10 ms and 1 in 20 late: {rms}")  # the docs' figures
        assert len(rms) == 2 and all(r <= MOST_RMS[board] for r in rms), rms
        assert sim.state(1)["collisions"] == 0
    finally:
        sim.stop()
