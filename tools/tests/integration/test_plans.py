"""servoctl's plans follow the servo's own: a jerk limit (item 70) averages
the trapezoid over a window (motion/planning.c), which the move takes
longer, and `move --wait`, `record` and the Python API's move_to plan it so.
Times are the simulated clock's."""
import csv

import pytest

from servoctl.cli import main
from servoctl.move_request import MoveRequest
from servoctl.servo import MotionSnapshot, Servo


def run(sim, capsys, *args):
    rc = main(["--port", sim.url, *args], clock=sim.clock_s)
    out = capsys.readouterr()
    assert "Traceback" not in out.err
    return rc, out.out, out.err


def jerk_limited(sim, capsys, jerk=5):
    assert run(sim, capsys, "config", "set", "1", "soft_start_on", "0")[0] == 0
    assert run(sim, capsys, "config", "set", "1", "jerk_limit", str(jerk))[0] == 0


def test_the_plan_takes_the_firmwares_window():
    # 60 deg in 500 ms with ramps of 20 ms: 0.0625 deg/ms^2 (6250 deg/s^2);
    # at 5 (deg/s^2)/ms the window spans both ramps' edges: 2 x 1256 ms.
    request = MoveRequest(interval_ms=500)
    assert request.planned_ms(600, 5) == (20, 460, 20, 2512)
    assert request.planned_ms(600, 0) == (20, 460, 20, 0)
    # The longest window the firmware takes: 4.1 s.
    assert request.planned_ms(1500, 5)[3] == 4096
    plan = request.plan(0, 600, 5)
    assert len(plan) == 3012 + 1 and plan[0] == 0 and abs(plan[-1] - 600) < 1e-9
    # Every step of the plan within the limit: 5000 deg/s^3.
    v = [b - a for a, b in zip(plan, plan[1:])]
    a = [y - x for x, y in zip(v, v[1:])]
    assert max(abs(y - x) for x, y in zip(a, a[1:])) * 100 * 1e6 <= 5000 * 1.01


def test_move_wait_follows_a_jerk_limited_plan(sim, capsys):
    jerk_limited(sim, capsys)
    rc, out, err = run(sim, capsys, "move", "1", "60", "--interval", "500", "--wait")
    assert rc == 0 and "planned 3012 ms" in out, (out, err)
    took = float(out.split(" after ")[1].split(" ms")[0])
    assert 2900 < took < 4500, out  # a late host polls later: the plan, not the host, is judged


def test_move_to_follows_a_jerk_limited_plan(sim, capsys):
    jerk_limited(sim, capsys)
    with sim.bus() as bus:
        result = Servo(bus, 1).move_to(60, duration_s=0.5, wait=True)
    assert result.arrived and 2.9 < result.took_s < 4.5, result


def test_record_plots_the_s_curve(sim, capsys, tmp_path):
    jerk_limited(sim, capsys)
    prefix = str(tmp_path / "rec")
    rc, out, err = run(sim, capsys, "record", "1", "60", "--interval", "500", "--out", prefix)
    assert rc == 0 and "(planned 3012 ms)" in out, (out, err)
    with open(prefix + ".csv") as f:
        rows = list(csv.DictReader(f))
    # The servo's own setpoint on the plan (a trapezoid's is up to 20 deg off).
    worst = max(abs(float(r["setpoint_deg"]) - float(r["planned_deg"])) for r in rows)
    assert worst < 0.5, worst


def test_a_streams_lead_in_waits_for_a_jerk_limited_move(sim, capsys, tmp_path):
    """90 deg in the lead-in's 0.5 s at 5 (deg/s^2)/ms: the window is the
    firmware's longest, 4.1 s, beyond the 3 s the trapezoid's wait gave."""
    jerk_limited(sim, capsys)
    path = tmp_path / "t.csv"
    path.write_text("time,1\n" + "".join(f"{k * 0.02:.2f},90\n" for k in range(20)))
    begun = sim.clock_s()
    # --report-only: the lead-in is judged here; the stream's own verdict on a
    # fast simulator would judge the host's pace too (test_stream.py's, paced).
    rc, out, err = run(sim, capsys, "stream", str(path), "--lead-in", "0.5", "--report-only")
    assert rc == 0, (out, err)
    assert sim.clock_s() - begun > 4.5


@pytest.mark.parametrize("request_, distance, jerk", [
    (MoveRequest(interval_ms=500), 600, 5),                              # both ramps' edges in one window
    (MoveRequest(interval_ms=1000, acc_ms=200, dec_ms=200), 900, 10),    # a window within the cruise
    (MoveRequest(velocity=3000, acc_ms=100, dec_ms=200), 900, 20),       # by velocity
    (MoveRequest(velocity=3000, acc_ms=300, dec_ms=300), 300, 20),       # too short for its ramps
    (MoveRequest(interval_ms=300, acc_ms=100, dec_ms=50), -450, 0),      # the trapezoid alone
])
def test_the_plan_ends_when_the_servos_profile_ends(sim, request_, distance, jerk):
    """The planned length against the servo's own, on its clock: the move
    began between the ReadMotion before it and the one after, and its
    profile ended between the last ReadMotion under way and the first that
    says it ended. A host that falls behind widens the bounds; it does not
    move them."""
    def us(a, b):
        return ((b.time_us - a.time_us) % 2**32) / 1000

    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.move(0, interval_ms=300)
        sim.sleep(0.5)
        s.write("jerk_limit", jerk)
        before = s.read_motion()
        s.send_move(distance, request_)
        first = last = s.read_motion()
        while not (snap := s.read_motion()).flags & MotionSnapshot.PROFILE_ENDED:
            assert us(first, snap) < 8000, "the profile never ended"
            last = snap
    planned_ms = request_.planned_s(distance - before.angle_decideg, jerk) * 1000
    assert us(first, last) - 2 <= planned_ms <= us(before, snap) + 2, (planned_ms, us(first, last), us(before, snap))
