"""A stream whose rate the wire cannot carry is refused before anything
moves, saying the wire's limit; a RobotLoop keeps its period on the
simulated clock."""
from servoctl.cli import main
from servoctl.stream import RobotLoop

# Host-paced (a stream at its rate on the wall clock): the simulator keeps
# real time (conftest.py).
REAL_TIME = True


def test_a_stream_faster_than_the_wire_is_refused_before_the_lead_in(sim, tmp_path, capsys):
    """500 Hz to one servo at 115 200 baud: a cycle is 44 bytes, so the
    wire carries 261.8 a second (on 7d81a12 it ran at 255 Hz, rc 0)."""
    path = tmp_path / "fast.csv"
    path.write_text("time,1\n" + "".join(f"{k * 0.002:.3f},{30 + k * 0.01:.2f}\n" for k in range(200)))
    rc = main(["--port", sim.url, "stream", str(path), "--lead-in", "0.5"], clock=sim.clock_s)
    err = capsys.readouterr().err
    assert rc == 2, err
    assert "500 Hz is beyond the wire" in err and "44 bytes" in err and "at most 261.8 Hz" in err, err
    sim.sleep(0.5)
    assert abs(sim.state(1)["angle"]) < 1.0  # no lead-in: nothing moved


def test_the_robot_loop_keeps_its_period_on_the_simulated_clock(sim):
    with sim.bus(timeout=0.2) as bus:
        loop = RobotLoop(bus, [1], 0.02)
        for _ in range(25):
            assert list(loop.cycle({1: 0.0})) == [1]
        rate = loop.rate()
    # 25 cycles, the last 24 periods after the first: a paced loop never
    # beats its period (the wire would take 262 a second), and its rate is
    # counted over those periods (before: 25 over 24 and a bit, 52 Hz). A
    # host starved of CPU may be late (a LoopLate warning), not judged here.
    assert rate.rate_hz <= 50.0 + 1e-6 and rate.cycles == 25, rate
