"""One frame of reference (frame.py): an angle means the horn's angle from
its origin in every command and in the Python API, single-turn unless asked
otherwise, never changed by what else is in the command; the angle limits
hold for every move servoctl makes. Each case below drove a horn somewhere
it was not asked to go."""
import re

import pytest

from servoctl.cli import main
from servoctl.protocol import Refused, ValueOutOfRange
from servoctl.servo import Servo


def run(sim, capsys, *args):
    rc = main(["--port", sim.url, *args], clock=sim.clock_s)
    out = capsys.readouterr()
    assert "Traceback" not in out.err and len(out.err.strip().splitlines()) <= 1, out.err
    return rc, out.out, out.err


def angle(sim, servo_id):
    return sim.state(servo_id)["angle"]


def prepare(sim, capsys, servo_id, limits=True):
    assert run(sim, capsys, "config", "set", str(servo_id), "soft_start_on", "0")[0] == 0
    if not limits:
        assert run(sim, capsys, "config", "set", str(servo_id), "angle_limit_on", "0")[0] == 0


def said_at(text: str) -> float:
    """The angle a refusal says the horn is at ("is at 200.1 deg"): it
    settles within a tolerance, not on the exact tenth."""
    found = re.search(r"is at (-?[\d.]+) deg", text)
    assert found, text
    return float(found[1])


def park(sim, capsys, servo_id, degrees):
    """A horn beyond the single turn, where a user's earlier multi-turn
    work left it."""
    rc, out, err = run(sim, capsys, "move", str(servo_id), str(degrees), "--multi-turn",
                       "--velocity", "600", "--wait")
    assert rc == 0, err
    assert abs(angle(sim, servo_id) - degrees) < 0.5


def test_move_to_beyond_a_turn_or_the_limits_is_refused_before_sending(sim):
    """Limits +-135 (the factory's): move_to(200) was a multi-turn move
    past them; now neither mode sends it."""
    with sim.bus() as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        with pytest.raises(ValueOutOfRange, match="beyond a single turn.*multi_turn=True"):
            s.move_to(200.0, wait=True)
        with pytest.raises(ValueOutOfRange, match=r"limits its angle to -135.0 deg..135.0 deg.*"
                                                  r"outside them"):
            s.move_to(200.0, multi_turn=True, wait=True)
        with pytest.raises(ValueOutOfRange, match="outside them"):
            s.move_to(170.0, wait=True)  # was sent, and clamped by the servo
    sim.sleep(0.3)
    assert abs(angle(sim, 1)) < 0.5


def test_a_single_turn_move_from_another_turn_is_refused(sim):
    """At 200 deg, move_to(170) drove the horn to 495 deg (the firmware
    takes 170 within the turn the horn is in)."""
    with sim.bus() as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.write("angle_limit_on", 0)
        assert abs(s.move_to(200.0, multi_turn=True, wait=True).angle / 10 - 200.0) <= 0.5
        with pytest.raises(Refused, match=r"would end at 5[23]\d\.\d deg.*multi_turn=True") as refused:
            s.move_to(170.0)
        assert abs(said_at(str(refused.value)) - 200.0) <= 0.5
        sim.sleep(0.3)
        assert abs(s.position_deg() - 200.0) <= 0.5
        s.move_to(170.0, multi_turn=True, wait=True)
        assert abs(s.position_deg() - 170.0) <= 0.5
        s.move_to(10.0, wait=True)  # back in turn 0: single-turn again
        assert abs(s.position_deg() - 10.0) <= 0.5


def test_move_from_720_degrees(sim, capsys):
    """'servoctl move 1 10 --wait' from 720 deg ended at 729.9 deg, exit 0."""
    prepare(sim, capsys, 1, limits=False)
    park(sim, capsys, 1, 720)
    rc, _, err = run(sim, capsys, "move", "1", "10", "--wait")
    at = re.search(r"is at (-?[\d.]+) deg.*would end at (-?[\d.]+) deg", err)
    assert rc == 2 and at and abs(float(at[1]) - 720.0) < 0.5, err  # refused before sending: 2
    assert float(at[2]) == pytest.approx(float(at[1]) + 10.0, abs=0.15)  # 0.1 deg steps
    assert "--multi-turn" in err
    sim.sleep(0.3)
    assert abs(angle(sim, 1) - 720.0) < 0.5
    rc, out, err = run(sim, capsys, "move", "1", "10", "--multi-turn", "--velocity", "600", "--wait")
    arrived = re.search(r"at (-?[\d.]+) deg after", out)
    assert rc == 0 and arrived and abs(float(arrived[1]) - 10.0) <= 0.5, (out, err)  # --tolerance


def test_a_sync_move_target_means_the_same_whatever_else_is_in_it(sim3, capsys):
    """'sync-move 2:10' and 'sync-move 1:200 2:10' sent servo 2 to 9.9 and
    369.9 deg: one target beyond 180 made every record multi-turn."""
    for i in (1, 2, 3):
        prepare(sim3, capsys, i, limits=i == 3)
    rc, out, _ = run(sim3, capsys, "sync-move", "2:10", "--interval", "300")
    assert rc == 0, out
    sim3.sleep(0.6)
    assert abs(angle(sim3, 2) - 10.0) < 0.5
    rc, _, err = run(sim3, capsys, "sync-move", "1:200", "2:-10", "--interval", "300")
    assert rc == 2 and "servo 1: 200.0 deg is beyond a single turn" in err and "--multi-turn" in err, err
    sim3.sleep(0.6)
    assert abs(angle(sim3, 1)) < 0.5 and abs(angle(sim3, 2) - 10.0) < 0.5  # nothing sent
    rc, out, err = run(sim3, capsys, "sync-move", "1:200", "2:-10", "--multi-turn", "--interval", "600")
    assert rc == 0, err
    sim3.sleep(1.0)
    assert abs(angle(sim3, 1) - 200.0) < 0.5 and abs(angle(sim3, 2) + 10.0) < 0.5
    # Servo 3 keeps the factory limits: a multi-turn record past them is refused.
    rc, _, err = run(sim3, capsys, "sync-move", "2:0", "3:150", "--multi-turn")
    assert rc == 2 and "servo 3 limits its angle" in err, err
    # Servo 1 is in turn 1 now: a single-turn record to it would not mean 20 deg.
    rc, _, err = run(sim3, capsys, "sync-move", "1:20", "2:0")
    assert rc == 2 and "servo 1 is at" in err and abs(said_at(err) - 200.0) <= 0.5, err
    rc, _, err = run(sim3, capsys, "sync-move", "1:90", "1:-90")
    assert rc == 2 and "servo 1 is given more than one target" in err, err


def test_a_broadcast_move_checks_every_servo_first(sim3, capsys):
    """'broadcast-move 0' left a servo at 360 deg."""
    for i in (1, 2, 3):
        prepare(sim3, capsys, i, limits=i != 3)
    park(sim3, capsys, 3, 360)
    rc, _, err = run(sim3, capsys, "broadcast-move", "20", "--interval", "300")
    assert rc == 2 and "servo 3 is at" in err and abs(said_at(err) - 360.0) <= 0.5, err
    sim3.sleep(0.6)
    assert [round(angle(sim3, i)) for i in (1, 2, 3)] == [0, 0, 360]
    assert run(sim3, capsys, "move", "3", "0", "--multi-turn", "--velocity", "600", "--wait")[0] == 0
    rc, out, _ = run(sim3, capsys, "broadcast-move", "20", "--interval", "300")
    assert rc == 0 and "3 servo(s) moving to 20.0 deg" in out
    sim3.sleep(0.6)
    assert [round(angle(sim3, i)) for i in (1, 2, 3)] == [20, 20, 20]
