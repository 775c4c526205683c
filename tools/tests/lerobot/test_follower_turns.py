"""servoctl.arm, the LeRobot follower's library, with a joint past a limit
across the wrap of its reading: a 6-servo arm whose servo 5 keeps limits of
-36.9..175.2 deg and rests at 188 deg. It was refused as "beyond one turn"
(servoctl info: 188.0 deg, 0 turns), and after the advised reset of its
turns (it then reads -172.0) connect() drove it 135 deg through the range
outside its limits, to the lower one. On servo_sim; the horn's angle is
the simulator's own, sampled every 5 ms of its clock."""
import pytest

from servoctl.arm import Arm
from servoctl.arm_turns import after_reset, way_back
from servoctl.errors import UsageError
from servoctl.servo import Servo
from servoctl.setpoints import Limits
from servoctl.sim import Simulator

from .test_follower_arm import FPS, state_dir  # noqa: F401 - the fixture

JOINTS = {f"Motor_{k}": k for k in range(5)} | {"wrist_roll": 5}
LOW, HIGH = -36.9, 175.2
TOLERANCE = 0.5  # deg: the servo's settling and the reading's 0.1


def resting_at(sim, deg: float, reset_turns: bool = False) -> Servo:
    """Servo 5 at rest at deg (multi-turn), released as a hand left it, its
    limits LOW..HIGH on; its turns reset after, where asked."""
    bus = sim.bus()
    s = Servo(bus, 5)
    s.write("angle_limit_on", 0)
    s.move_to(deg, duration_s=1.0, multi_turn=True, wait=True)
    s.stop("release")
    Arm(bus, JOINTS, fps=FPS, watchdog_ms=0).store_ranges({"wrist_roll": (LOW, HIGH)})
    if reset_turns:
        s.reset_multi_turn()
        bus.sleep(0.01)
    return s


def connect_sampled(sim, monkeypatch, arm: Arm) -> tuple:
    """hold_here(), the simulator's angle of servo 5 sampled every 5 ms
    while connect waits: (held, [angles])."""
    bus, sleep, seen = arm.bus, arm.bus.sleep, []

    def sampled(seconds):
        end = sim.clock_s() + seconds
        while sim.clock_s() < end:
            sleep(min(0.005, end - sim.clock_s()))
            seen.append(sim.state(5)["angle"])

    monkeypatch.setattr(bus, "sleep", sampled)
    try:
        held = arm.hold_here()
    finally:
        monkeypatch.undo()
    return held, seen


@pytest.mark.parametrize("reset_turns", [False, True], ids=["as-it-rests", "turns-reset"])
def test_a_joint_past_its_limit_across_the_wrap_comes_back_the_short_way(monkeypatch, reset_turns):
    """188 deg (0 turns), and the same horn after the advised reset (-172.0):
    each comes back 12.8 deg to 175.2, never through the range outside the
    limits; then the first actions ramp from there within them."""
    with Simulator(ids=list(JOINTS.values()), paced=True) as sim:
        s = resting_at(sim, 188.0, reset_turns)
        start = sim.state(5)["angle"]
        assert start == pytest.approx(188.0, abs=0.3)
        assert s.multi_turn_angle()[0] / 10 == pytest.approx(-172.0 if reset_turns else 188.0, abs=0.3)
        arm = Arm(s.bus, JOINTS, fps=FPS).open()
        held, seen = connect_sampled(sim, monkeypatch, arm)
        assert held["wrist_roll"] == pytest.approx(HIGH, abs=0.1), held
        assert seen and all(HIGH - TOLERANCE <= a <= start + TOLERANCE for a in seen), (min(seen), max(seen))
        assert s.multi_turn_angle()[0] / 10 == pytest.approx(HIGH, abs=0.2)  # the reading in the limits' turn
        t0 = sim.clock_s()
        for k in range(2 * FPS):  # toward the lower limit: through the range, inside it
            arm.send({"wrist_roll": 170.0 - 5 * k})
            while sim.clock_s() < t0 + (k + 1) / FPS:
                sim.sleep(0.005)
                horn = sim.state(5)["angle"]
                assert LOW - TOLERANCE <= horn <= HIGH + TOLERANCE, horn
        assert sim.state(5)["angle"] < 150
        arm.close()


def test_a_joint_a_turn_off_within_its_limits_is_refused_with_advice_that_holds():
    """At 175.0 deg reading -185.0 (0 turns in 'servoctl info'; a horn
    turned down across the wrap): within its limits, a turn off its reading.
    It is refused, left holding, with what the servo reads and what a reset
    gives; after that reset connect() holds it where it is."""
    with Simulator(ids=list(JOINTS.values()), paced=True) as sim:
        s = resting_at(sim, -185.0)
        bus = s.bus
        before, reads = sim.state(5)["angle"], s.multi_turn_angle()
        assert reads[1] == 0 and reads[0] == pytest.approx(-1850, abs=2), reads
        with pytest.raises(UsageError) as e:
            Arm(bus, JOINTS, fps=FPS, watchdog_ms=0).open().hold_here()
        said = str(e.value)
        assert f"wrist_roll (servo 5) reads {reads[0] / 10:.1f} deg ('servoctl info 5')" in said, said
        assert "beyond one turn" not in said and f"it then reads {reads[0] / 10 + 360:.1f} deg" in said, said
        sim.sleep(0.3)
        assert sim.state(5)["angle"] == pytest.approx(before, abs=0.3)  # held, not moved
        s.stop("release")
        s.reset_multi_turn()
        bus.sleep(0.01)
        held = Arm(bus, JOINTS, fps=FPS, watchdog_ms=0).open().hold_here()
        assert held["wrist_roll"] == pytest.approx(175.0, abs=0.2)
        sim.sleep(0.3)
        assert sim.state(5)["angle"] == pytest.approx(before, abs=0.3)


@pytest.mark.parametrize("reading, place, limit, turns", [
    (1880, 1880, 1752, 0),     # 12.8 past the upper limit, not 135.1 below the lower
    (-1720, 1880, 1752, -1),   # the same horn, its turns reset: across the wrap
    (5480, 1880, 1752, 1),     # a turn more
    (-1850, 1750, None, -1),   # within the limits, a turn off
    (1000, 1000, None, 0),
    (-1000, -1000, -369, 0),   # 63.1 below the lower limit, not 81.2 past the upper (the way round)
    (-2300, 1300, None, -1),
])
def test_the_way_back_is_taken_modulo_a_turn(reading, place, limit, turns):
    way = way_back(reading, Limits(-369, 1752))
    assert (way.place, way.limit, way.turns) == (place, limit, turns)


def test_with_the_limits_off_a_reading_past_the_wrap_counts_a_turn():
    assert way_back(1880, Limits()).turns == 1 and after_reset(1880, 0) == -1720
    assert way_back(-1720, Limits()).turns == 0
    assert after_reset(1880, -100) == 1880 and after_reset(1880, 100) == -1720  # the center offset: as servo_sim
