"""servoctl stream and Stream keep a real arm safe: a file is
checked whole, against the servo's limits too, before anything moves; the
lead-in is waited for (soft start included), checked, and keeps a bus
watchdog fed; a power cycle does not put the joint a turn away. Time is the
simulator's."""
import math

import pytest

from servoctl.cli import main
from servoctl.errors import UsageError, ValueOutOfRange
from servoctl.servo import Servo
from servoctl.stream import Limits, RobotLoop, Stream

from ..stream_report import lead_in_of

# Host-paced (a stream at its rate on the bus's clock): the simulator is
# paced (conftest.py), so the stream's verdict (exit 0 within its
# tolerance, on time) is the servo's whatever the load.
PACED = True


def write_csv(path, rows, period_s=0.02):
    """rows: one angle (deg, or a text) per row, for servo 1."""
    lines = ["time,1"] + [f"{k * period_s:.3f},{a}" for k, a in enumerate(rows)]
    path.write_text("\n".join(lines) + "\n")
    return path


def stream(sim, path, lead_in=0.5):
    return main(["--port", sim.url, "stream", str(path), "--lead-in", str(lead_in)], clock=sim.clock_s)


def still_where_it_was(sim, bus, angle_deg, settle_s=0.5):
    """The horn and the servo's target after settle_s: nothing was sent
    that moves it."""
    sim.sleep(settle_s)
    assert abs(sim.state(1)["angle"] - angle_deg) < 0.5
    assert abs(Servo(bus, 1).read_motion().target_decideg - round(angle_deg * 10)) <= 1


def ramp(first, last, count):
    return [f"{first + (last - first) * k / (count - 1):.3f}" for k in range(count)]


@pytest.mark.parametrize("bad, why", [
    ("1e7", "angle must be -368640..368640 deg"),    # beyond the multi-turn range
    ("abc", "'abc' is not a number"),
    ("nan", "finite"),
    ("65", "deg/s, beyond the 750 deg/s"),            # 55 deg in 20 ms
    ("300", "angle_min, angle_max, angle_limit_on"),  # beyond angle_max 135 (factory)
])
def test_a_bad_row_is_named_by_its_line_and_nothing_moves(sim, tmp_path, capsys, bad, why):
    """60 good rows, then a bad one. On c285aa0 the
    lead-in and 60 rows ran before the bad row was seen (and the last good
    row's velocity came from it); a row beyond the angle limits or the
    servo's speed was streamed."""
    with sim.bus(timeout=0.2) as bus:
        Servo(bus, 1).write("soft_start_on", 0)
    rows = ramp(5.0, 10.0, 60) + [bad] + ramp(10.0, 10.0, 10)
    rc = stream(sim, write_csv(tmp_path / "bad.csv", rows))
    err = capsys.readouterr().err
    assert rc == 2, err  # docs/servoctl.md: usage, nothing was sent
    assert "bad.csv line 62:" in err and why in err, err
    with sim.bus(timeout=0.2) as bus:
        still_where_it_was(sim, bus, 0.0)


def test_stream_refuses_a_setpoint_beyond_the_limits_it_reads_from_the_servo(sim):
    """Stream reads the angle limits from the servo and
    refuses a setpoint outside them, or a step faster than the servo moves,
    sending nothing; c285aa0 sent both (the horn went to 300 deg)."""
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("angle_max", 900)
        st = Stream(bus, [1], 0.02)
        assert st.limits[1] == Limits(-1350, 900)
        with pytest.raises(ValueOutOfRange, match=r"-135.0..90.0 deg .*300.0 deg is outside"):
            st.send({1: 300.0})
        with pytest.raises(ValueOutOfRange, match="beyond the 750 deg/s"):
            st.send({1: 0.0}, {1: 900.0})  # a velocity the servo would clamp
        st.send({1: 10.0})
        with pytest.raises(ValueOutOfRange, match=r"100.0 deg in 20 ms .* 5000 deg/s"):
            st.send({1: -90.0})
        assert st.sent == 1
        sim.sleep(0.3)
        assert abs(s.read_motion().target_decideg - 100) <= 1  # only the good setpoint went
        s.write("angle_limit_on", 0)
        assert Stream(bus, [1], 0.02).limits[1] == Limits()  # off: the multi-turn range only


def test_the_stream_waits_for_a_soft_started_lead_in(sim, tmp_path, capsys):
    """After a power cycle the first move takes the soft
    start's 3 s; on c285aa0 the stream began 0.7 s in and replaced it (peak
    error 105.6 deg), and said nothing."""
    with sim.bus(timeout=0.2) as bus:
        assert Servo(bus, 1).read("soft_start_on") == 1  # factory: 3000 ms
    sim.control("powercycle 1")
    sim.sleep(0.6)
    path = write_csv(tmp_path / "t.csv", [f"{60 + 10 * math.sin(k / 10):.3f}" for k in range(100)])
    begun = sim.clock_s()
    rc = stream(sim, path)
    out = capsys.readouterr().out
    print(out)
    assert rc == 0
    # At the first row when the stream began (the report's peak error is the
    # host's too: a loaded PC sends late, and it grows).
    assert lead_in_of(out)[1] == pytest.approx(60.0, abs=0.5), out
    assert "soft start" in out
    assert sim.clock_s() - begun > 3.0 + 99 * 0.02


def test_the_lead_in_keeps_the_bus_watchdog_fed(sim, tmp_path, capsys):
    """With docs/safety.md's 100 ms watchdog the lead-in
    of c285aa0 (a silent second and more) tripped it and the stream began
    35 deg off."""
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.write("watchdog_ms", 100)
        s.move(0, interval_ms=100)  # held, under control: the watchdog watches
        sim.sleep(0.05)
    rc = stream(sim, write_csv(tmp_path / "t.csv", ramp(40.0, 50.0, 50)), lead_in=1.0)
    out = capsys.readouterr().out
    print(out)
    assert rc == 0
    # A watchdog that acted in the lead-in would have stopped it short (rc 1).
    assert "servo 1: from 0.0 deg to 40.0 deg" in out, out


def test_a_lead_in_that_does_not_arrive_is_an_error_and_nothing_is_streamed(sim, tmp_path, capsys):
    """A lead-in blocked short of the first row; c285aa0
    streamed regardless and exited 0."""
    with sim.bus(timeout=0.2) as bus:
        Servo(bus, 1).write("soft_start_on", 0)
    sim.control("stop 20")  # a mechanical stop at 20 deg
    rc = stream(sim, write_csv(tmp_path / "t.csv", ramp(60.0, 70.0, 50)))
    captured = capsys.readouterr()
    assert rc == 1, captured
    assert "lead-in to the first row (60.0 deg)" in captured.err, captured.err
    assert "Nothing was streamed" in captured.err
    assert "setpoints at" not in captured.out


def test_a_stream_after_a_power_cycle_stays_in_the_joints_turn(sim, tmp_path, capsys):
    """At -30 deg, powered off and on, servo_sim read
    330 deg; the lead-in to a trajectory at -30 deg turned the joint a
    whole turn, and the report said RMS 0.00 deg, as it judged the servo's
    own reading (a turn off) with the lead-in left out. Now the reading is
    -30 deg, the joint stays, and the report shows each lead-in."""
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.move(-300, interval_ms=500)
        sim.sleep(1.0)
    sim.control("powercycle 1")
    sim.sleep(0.6)
    rows = [f"{-30 + 5 * math.sin(k / 10):.3f}" for k in range(100)]
    rc = stream(sim, write_csv(tmp_path / "t.csv", rows), lead_in=1.0)
    out = capsys.readouterr().out
    print(out)
    assert rc == 0
    assert abs(sim.state(1)["angle"] - float(rows[-1])) < 2.0, out  # the joint itself, not a turn away
    assert lead_in_of(out) == pytest.approx((-30.0, -30.0), abs=0.15), out  # within a count either side
    assert "warning" not in out


def test_the_report_warns_of_a_lead_in_of_half_a_turn_or_more(sim, tmp_path, capsys):
    """The tracking error is the servo's reading against the file: a lead-in
    that turned the joint far is said with it."""
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.write("angle_limit_on", 0)
    rc = stream(sim, write_csv(tmp_path / "t.csv", ramp(200.0, 200.0, 20)), lead_in=1.0)
    out = capsys.readouterr().out
    assert rc == 0
    assert "warning: servo 1 turned 200." in out and "deg to reach the first row" in out, out


def test_a_period_that_would_starve_the_watchdog_is_refused_before_anything_is_sent(sim, tmp_path, capsys):
    """docs/safety.md's 100 ms watchdog, action release, and a file 0.5 s a
    row: c285aa0 streamed it, the servo was released once a row, and the
    command exited 0. Now the file's period is checked against each
    servo's watchdog_ms first (at most half of it): exit 2, nothing sent.
    Stream and RobotLoop check it when made, from the limits they read."""
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.write("watchdog_ms", 100)
        s.write("watchdog_action", 2)  # release
    rc = stream(sim, write_csv(tmp_path / "slow.csv", ramp(30.0, 40.0, 9), period_s=0.5))
    captured = capsys.readouterr()
    assert rc == 2, captured
    for said in ("servo 1's bus watchdog (watchdog_ms 100 ms)", "setpoints 500 ms apart",
                 "a period of at most 50 ms", "config set 1 watchdog_ms 1000", "nothing was sent"):
        assert said in captured.err, captured.err
    assert "lead-in" not in captured.out and "setpoints at" not in captured.out, captured.out
    with sim.bus(timeout=0.2) as bus:
        still_where_it_was(sim, bus, 0.0)  # no lead-in to 30 deg
        for period_s in (0.5, 0.051):
            with pytest.raises(UsageError, match=f"setpoints {round(period_s * 1000)} ms apart"):
                Stream(bus, [1], period_s)
            with pytest.raises(UsageError, match="watchdog_ms 100 ms"):
                RobotLoop(bus, [1], period_s)
        assert Stream(bus, [1], 0.05).limits[1].watchdog_ms == 100  # half: taken
        Servo(bus, 1).write("watchdog_ms", 0)
        assert Stream(bus, [1], 0.5).limits[1].watchdog_ms == 0  # off: any period
