"""Jerk-limited moves on the simulated servo (item 70): the same angle
move with and without a jerk limit. The limited one's profile ends the
window a / J later (docs/decisions-motion.md, "Jerk-limited moves") and it
arrives as the trapezoid does. Time is the simulator's: how long the servo
executed the move (status bit 0 as the simulator saw it, last_move_ms),
from the pass that began it to the tick it arrived."""
from servoctl.servo import MotionSnapshot, Servo


def move_time_ms(sim, jerk_limit: int) -> tuple:
    """(ms the servo executed the move, the angle it comes to rest at in
    0.1 deg) for 90 deg in 1000 ms with ramps of 200 ms. Once the profile
    has ended (ReadMotion's flag) the move is judged on the simulated
    clock: a poll of the servo's own clock that a loaded host sent late had
    measured its end late (1010 ms)."""
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.write("jerk_limit", 0)
        s.move(0, interval_ms=300)
        sim.sleep(0.5)
        s.write("jerk_limit", jerk_limit)
        s.move(900, interval_ms=1000, acc_ms=200, dec_ms=200)
        first = s.read_motion()
        assert not first.flags & MotionSnapshot.PROFILE_ENDED
        while not (snap := s.read_motion()).flags & MotionSnapshot.PROFILE_ENDED:
            assert (snap.time_us - first.time_us) % 2**32 < 3_000_000, "the profile never ended"
        sim.sleep(0.3)
        return sim.state(1)["last_move_ms"], s.read_motion().angle_decideg


def test_a_jerk_limit_smooths_a_move_at_its_cost_in_time(sim):
    plain_ms, plain_rest = move_time_ms(sim, 0)
    smooth_ms, smooth_rest = move_time_ms(sim, 10)
    # 900 decideg over 200 + 600 + 200 ms: a = 0.005625 decideg/ms^2; at
    # 10 (deg/s^2)/ms (1e-4 decideg/ms^3, 167 / 2^24 as the firmware takes it)
    # the window is 57 ms. Each move arrives at its profile's end, within a
    # tick or two (1000.0 and 1056.1 ms measured).
    assert 997 <= plain_ms <= 1003, plain_ms
    assert 52 <= smooth_ms - plain_ms <= 62, (plain_ms, smooth_ms)
    assert abs(plain_rest - 900) <= 5 and abs(smooth_rest - 900) <= 5, (plain_rest, smooth_rest)


def test_the_jerk_limit_takes_what_its_item_says(sim):
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("jerk_limit", 65535)
        assert s.read("jerk_limit") == 65535
        s.write("jerk_limit", 0)
        assert s.read("jerk_limit") == 0


def test_a_jerk_limited_move_the_motor_cannot_follow_still_arrives(sim):
    """90 deg in 300 ms at 2 W: the motor cannot follow the plan (its
    current limit holds it back, and the profile's clock slows); with a jerk
    limit the horn still comes to the target without passing it by more
    than a degree, and rests within 0.5 deg."""
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.move(0, interval_ms=300)
        sim.sleep(0.5)
        s.write("jerk_limit", 50)
        s.move(900, interval_ms=300, acc_ms=50, dec_ms=50, power_mw=2000)
        angles, held_back = [], False
        for _ in range(100):
            sim.sleep(0.02)
            snap = s.read_motion()
            angles.append(snap.angle_decideg)
            held_back |= snap.limiter in ("power", "current")
        assert held_back, "the motor kept up: not the case this test is for"
        assert max(angles) <= 910 and abs(angles[-1] - 900) <= 5, (max(angles), angles[-1])
