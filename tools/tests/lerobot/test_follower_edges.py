"""servoctl.arm at the edges an attacker found: a joint left out of the
first actions, a crash between the two watchdog writes, a servo that
holds the follower's own setting with no record of its own, a servo
power-cycled mid-run, records and IDs that are not what they should be.
On servo_sim; time is the simulator's."""
import json
import logging
import os
import threading

import pytest

from servoctl.arm import Arm
from servoctl.errors import ServoError, UsageError
from servoctl.servo import Servo
from servoctl.sim import Simulator
from servoctl.watchdog_record import WatchdogRecords

from .test_follower_arm import FACTORY_WATCHDOG, FPS, state_dir, watchdog  # noqa: F401 - the fixture too

RAMP_TOP = 56  # 45 deg/s, give or take the servo's ripple on the paced clock's frames


def frames(sim, arm, t0: float, first: int, count: int, goal, watch: int) -> float:
    """count frames from frame first on (goal(k): the action), each on the
    simulated clock; the peak horn speed of servo watch."""
    peak = 0.0
    for k in range(first, first + count):
        arm.send(goal(k))
        while sim.clock_s() < t0 + (k + 1) / FPS:
            sim.sleep(0.005)
            peak = max(peak, abs(sim.state(watch)["velocity"]))
    return peak


def test_a_joint_left_out_of_the_first_action_still_ramps():
    """The first action named only a: b's gap was taken as 0, b left the
    ramp, and when first asked 40 deg away it jumped at the motor's top
    speed; a first send_action({}) took every joint out of the ramp."""
    with Simulator(ids=[1, 2], paced=True) as sim:
        arm = Arm(sim.bus(), {"a": 1, "b": 2}, fps=FPS, watchdog_ms=0).open()
        held = arm.hold_here()
        t0 = sim.clock_s()
        frames(sim, arm, t0, 0, 1, lambda k: {"a": held["a"] + 40}, 2)
        assert "b" in arm.ramp.joints  # not asked, not reached
        peak = frames(sim, arm, t0, 1, 45, lambda k: {"a": held["a"] + 40, "b": held["b"] + 40}, 2)
        assert peak <= RAMP_TOP, peak
    with Simulator(ids=[1, 2], paced=True) as sim:
        arm = Arm(sim.bus(), {"a": 1, "b": 2}, fps=FPS, watchdog_ms=0).open()
        held = arm.hold_here()
        t0 = sim.clock_s()
        assert arm.send({}) == {n: round(d, 1) for n, d in held.items()}
        assert arm.ramp.joints == {"a", "b"}
        peak = frames(sim, arm, t0, 1, 45, lambda k: {"a": held["a"] + 40, "b": held["b"] - 40}, 1)
        assert peak <= RAMP_TOP, peak


class Crash(BaseException):
    """The process killed (kill -9, a pulled plug) right after a write."""


@pytest.fixture
def crash_after(monkeypatch):
    """crash_after(item, n): the n-th write of item from now on raises Crash
    once it has reached the servo."""
    def arm(item: str, n: int):
        count, write = [0], Servo.write

        def crashing(self, name, value, *a, **k):
            out = write(self, name, value, *a, **k)
            if name == item:
                count[0] += 1
                if count[0] == n:
                    monkeypatch.setattr(Servo, "write", write)
                    raise Crash(f"after {name} = {value}")
            return out
        monkeypatch.setattr(Servo, "write", crashing)
    return arm


@pytest.mark.parametrize("phase", ["open", "close"])
def test_a_crash_between_the_two_watchdog_writes_leaves_the_servos_own(phase, crash_after):
    """Items 64 then 65: a crash between them left 500 ms with the servo's
    own action (connecting) or its own ms with hold (closing), which the
    next run took for the servo's own, for good."""
    with Simulator(ids=[1], fast=True) as sim:
        bus = sim.bus()
        Servo(bus, 1).write("watchdog_action", 2)  # the servo's own: off, release
        own = (0, 2)
        arm = Arm(bus, {"a": 1})
        if phase == "open":
            crash_after("watchdog_ms", 1)
            with pytest.raises(Crash):
                arm.open()
        else:
            arm.open()
            crash_after("watchdog_ms", 1)
            with pytest.raises(Crash):
                arm.close()
        assert watchdog(bus, 1) in ((500, 2), (0, 0))  # half written
        again = Arm(bus, {"a": 1}).open()
        assert watchdog(bus, 1) == (500, 0)
        again.close()
        assert watchdog(bus, 1) == own


@pytest.mark.parametrize("ms", [500, 1000])
def test_the_followers_own_setting_with_no_record_here_is_said_and_not_kept(tmp_path, caplog, ms):
    """Another computer's (or user's, or state folder's) run that did not
    end cleanly left 500 ms, hold: with no record here it was silently
    taken for the servo's own, and put back on close; so too by a run
    that arms its own 1000 ms."""
    with Simulator(ids=[1, 2], fast=True) as sim:
        bus = sim.bus()
        Arm(bus, {"a": 1, "b": 2}, records=WatchdogRecords(tmp_path / "elsewhere")).open()  # never closed
        with caplog.at_level(logging.WARNING, logger="servoctl.arm"):
            arm = Arm(bus, {"a": 1, "b": 2}, watchdog_ms=ms).open()
        said = caplog.text
        assert "a (servo 1): its bus watchdog holds 500 ms, hold, the follower's own setting" in said, said
        assert "no record" in said and "servoctl config set 1 watchdog_ms 500" in said, said
        arm.close()
        assert [watchdog(bus, i) for i in (1, 2)] == [FACTORY_WATCHDOG] * 2


def test_a_record_that_cannot_be_removed_leaves_the_next_servos_put_back(state_dir):
    """close() raised the bare OSError of the first record it could not
    remove, and the servos after it kept the follower's setting."""
    with Simulator(ids=[1, 2], fast=True) as sim:
        bus = sim.bus()
        arm = Arm(bus, {"a": 1, "b": 2}).open()
        first = arm.records.path(Servo(bus, 1).read("serial"), bus.port)
        first.unlink()
        first.mkdir()  # unlink() fails on it
        with pytest.raises(ServoError) as e:
            arm.close()
        assert str(first) in str(e.value) and "record of the servo's own bus watchdog" in str(e.value), e.value
        assert [watchdog(bus, i) for i in (1, 2)] == [FACTORY_WATCHDOG] * 2


def test_a_state_folder_that_cannot_be_made_is_named(tmp_path):
    (tmp_path / "file").write_text("")
    with Simulator(ids=[1], fast=True) as sim:
        bus = sim.bus()
        with pytest.raises(ServoError) as e:
            Arm(bus, {"a": 1}, records=WatchdogRecords(tmp_path / "file" / "watchdog")).open()
        assert "record of the servo's own bus watchdog" in str(e.value) and "SERVOCTL_STATE_DIR" in str(e.value)
        assert watchdog(bus, 1) == FACTORY_WATCHDOG  # nothing written before it is kept


@pytest.mark.parametrize("own", [["x", 1], [70000, 0], [0], "off"])
def test_a_malformed_record_is_dropped_with_a_warning(state_dir, own, caplog):
    """A record whose own setting was not two items in range made close()
    fail at every run."""
    with Simulator(ids=[1], fast=True) as sim:
        bus = sim.bus()
        Arm(bus, {"a": 1}).open()  # never closed: the servo holds 500 ms, hold
        path = WatchdogRecords().path(Servo(bus, 1).read("serial"), bus.port)
        path.write_text(f'{{"own": {json.dumps(own)}, "wrote": [500, 0]}}')
        with caplog.at_level(logging.WARNING, logger="servoctl.arm"):
            arm = Arm(bus, {"a": 1}).open()
        assert "is not a record of a watchdog setting" in caplog.text, caplog.text
        arm.close()
        assert watchdog(bus, 1) == FACTORY_WATCHDOG


def test_a_fifo_in_place_of_a_record_does_not_hang_connect(state_dir):
    with Simulator(ids=[1], fast=True) as sim:
        bus = sim.bus()
        path = WatchdogRecords().path(Servo(bus, 1).read("serial"), bus.port)
        path.parent.mkdir(parents=True)
        os.mkfifo(path)
        done = []
        opening = threading.Thread(target=lambda: done.append(Arm(bus, {"a": 1}).open()), daemon=True)
        opening.start()
        opening.join(30)
        if not done:  # hung on the FIFO's open: a writer lets it go
            os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))
            opening.join(5)
            pytest.fail("connect hung opening a FIFO named like a record")
        done[0].close()
        assert watchdog(bus, 1) == FACTORY_WATCHDOG


def test_a_planted_link_is_not_followed(state_dir, tmp_path):
    """The record was written to .SERIAL.json.PID first, following a
    link planted there."""
    victim = tmp_path / "victim"
    victim.write_text("mine")
    with Simulator(ids=[1], fast=True) as sim:
        bus = sim.bus()
        path = WatchdogRecords().path(Servo(bus, 1).read("serial"), bus.port)
        path.parent.mkdir(parents=True)
        path.with_name(f".{path.name}.{os.getpid()}").symlink_to(victim)
        Arm(bus, {"a": 1}).open().close()
    assert victim.read_text() == "mine"


def test_a_servo_that_restarts_mid_run_ramps_again_from_where_it_is(caplog):
    """Power-cycled under a load (items 64-72 back to the factory's, the
    output released), the servo fell 18 deg and was then driven back at
    276 deg/s with no ramp, its watchdog off, and nothing said."""
    with Simulator(ids=[1, 2], paced=True) as sim:
        bus = sim.bus()
        arm = Arm(bus, {"a": 1, "b": 2}, fps=FPS).open()
        held = arm.hold_here()
        goal = {"a": held["a"] + 30, "b": held["b"]}
        t0 = sim.clock_s()
        frames(sim, arm, t0, 0, 60, lambda k: goal, 1)
        assert abs(sim.state(1)["angle"] - goal["a"]) < 0.5
        sim.control("load 0.6 1")
        sim.control("powercycle 1")
        angles = []
        with caplog.at_level(logging.WARNING, logger="servoctl.arm"):
            for k in range(60, 100):
                if k == 64:
                    sim.control("load 0 1")  # let go within the bootloader's 0.2 s
                frames(sim, arm, t0, k, 1, lambda k: goal, 1)
                angles.append(sim.state(1)["angle"])
        fallen = min(angles)
        assert fallen < goal["a"] - 10, angles  # it did fall: released at power-up
        rises = [b - a for a, b in zip(angles, angles[6:])]  # over 0.2 s
        assert max(rises) <= 45 * 0.2 + 2, (max(rises), angles)
        assert "a (servo 1): its bus watchdog read 0 ms, not the arm's 500 ms: it restarted" in caplog.text
        assert watchdog(bus, 1) == (500, 0)
        arm.close()
        assert [watchdog(bus, i) for i in (1, 2)] == [FACTORY_WATCHDOG] * 2


def test_a_servo_that_restarts_outside_its_limits_goes_to_the_nearest_and_ramps(caplog):
    """Power-cycled under a load, it fell below its lower limit: the ramp
    started where it fell, outside the limits, and the next send raised
    ValueOutOfRange advising to connect again or calibrate."""
    with Simulator(ids=[1, 2], paced=True) as sim:
        bus = sim.bus()
        here = Arm(bus, {"a": 1, "b": 2}, watchdog_ms=0).open().positions()
        low = here["a"] + 24  # the goal 6 deg above it: the fall (18 deg) ends below it
        Arm(bus, {"a": 1, "b": 2}, watchdog_ms=0).open().store_ranges(
            {"a": (low, low + 66), "b": (here["b"] - 90, here["b"] + 90)})
        arm = Arm(bus, {"a": 1, "b": 2}, fps=FPS).open()
        held = arm.hold_here()
        goal = {"a": low + 6, "b": held["b"]}
        t0 = sim.clock_s()
        frames(sim, arm, t0, 0, 60, lambda k: goal, 1)
        sim.control("load 0.6 1")
        sim.control("powercycle 1")
        angles, times = [], []
        with caplog.at_level(logging.WARNING, logger="servoctl.arm"):
            for k in range(60, 110):
                if k == 64:
                    sim.control("load 0 1")  # let go within the bootloader's 0.2 s
                frames(sim, arm, sim.clock_s(), 0, 1, lambda k: goal, 1)  # one send waits for the move
                times.append(sim.clock_s())
                angles.append(sim.state(1)["angle"])
        assert min(angles) < low - 5, angles  # it fell outside its limits
        assert "it restarted" in caplog.text and "outside its angle limits: moved to the nearest" in caplog.text, \
            caplog.text
        # Over 0.2 s or more (the move to the limit takes one send's while): the ramp's speed, give or take.
        rates = [(b - a) / (u - t) for a, b, t, u in zip(angles, angles[6:], times, times[6:])]
        assert max(rates) <= 45 + 10, (max(rates), angles)
        assert abs(angles[-1] - goal["a"]) < 0.5, angles  # ramped to the goal from the limit
        assert watchdog(bus, 1) == (500, 0)
        arm.close()


def test_a_servo_that_restarts_outside_its_limits_and_is_blocked_names_the_restart():
    """Held where it fell, it cannot reach its limit: the error says it
    restarted, not that the limits were changed since connect."""
    with Simulator(ids=[1], paced=True) as sim:
        bus = sim.bus()
        arm = Arm(bus, {"a": 1}, fps=FPS).open()
        held = arm.hold_here()
        frames(sim, arm, sim.clock_s(), 0, 3, lambda k: held, 1)
        lim = arm.limits[1]
        # The arm's limits as read at connect: 20-40 deg above it (the servo's own stay wide, so its
        # move toward them is taken, and only the load stops it).
        lim.angle_min, lim.angle_max = round(held["a"] * 10) + 200, round(held["a"] * 10) + 400
        sim.control("powercycle 1")
        sim.control("load 5 1")  # held against it: it falls, and cannot rise
        with pytest.raises(ServoError) as e:
            t0 = sim.clock_s()
            frames(sim, arm, t0, 0, 30, lambda k: {"a": held["a"] + 25}, 1)
        said = str(e.value)
        assert "a (servo 1) restarted mid-run" in said and "outside its angle limits" in said, said
        assert "were they changed since" not in said, said
        sim.control("load 0 1")
        arm.close()


def test_one_id_in_two_joints_is_refused_naming_both():
    with pytest.raises(UsageError) as e:
        Arm(None, {"a": 1, "b": 2, "c": 1})
    assert "a and c (servo 1)" in str(e.value), e.value


@pytest.mark.parametrize("fps", [0, -30.0, float("nan"), float("inf"), True])
def test_an_fps_that_is_no_rate_is_refused_before_anything_is_written(fps):
    with pytest.raises(UsageError) as e:
        Arm(None, {"a": 1}, fps=fps)
    assert "fps is the loop's frames a second" in str(e.value), e.value


@pytest.mark.parametrize("setting", [{"watchdog_ms": -5}, {"watchdog_ms": 70000}, {"watchdog_ms": 3.7},
                                     {"watchdog_ms": "500"}, {"watchdog_ms": True}, {"ramp_speed_deg_s": "5"},
                                     {"ramp_speed_deg_s": None}])
def test_a_setting_of_the_wrong_kind_is_refused_before_anything_is_written(setting):
    """A watchdog_ms of -5 or 3.7 wrote the watchdog record, then failed in
    the write (a bare struct.error); a ramp speed of "5" raised TypeError."""
    with pytest.raises(UsageError) as e:
        Arm(None, {"a": 1}, **setting)
    assert str(e.value).startswith(next(iter(setting)) + " is "), e.value


def test_two_simulators_keep_their_own_records(state_dir, caplog):
    """servo_sim's serials (0x51a0UUNN) are the same in every simulator:
    arm B's clean run removed arm A's record (one file a serial), and A's
    next run put back the factory's setting, not A's own, blaming another
    computer. A real servo's serial is its own: its record keeps its name
    whatever the device is called."""
    assert WatchdogRecords().path(0x51A00001, "/dev/ttyUSB0").name == "51a00001.json"
    with Simulator(ids=[1], fast=True) as sa, Simulator(ids=[1], fast=True) as sb:
        ba, bb = sa.bus(), sb.bus()
        assert Servo(ba, 1).read("serial") == Servo(bb, 1).read("serial")  # as the simulator gives them
        own = (2000, 2)
        Servo(ba, 1).write("watchdog_ms", own[0])
        Servo(ba, 1).write("watchdog_action", own[1])
        Arm(ba, {"j": 1}).open()  # its run never ends cleanly
        Arm(bb, {"j": 1}).open().close()  # the other follower's clean run
        assert watchdog(bb, 1) == FACTORY_WATCHDOG
        with caplog.at_level(logging.WARNING, logger="servoctl.arm"):
            again = Arm(ba, {"j": 1}).open()
        assert "another computer" not in caplog.text, caplog.text
        assert "which a run that did not end cleanly wrote" in caplog.text, caplog.text
        again.close()
        assert watchdog(ba, 1) == own


def test_the_streams_period_is_told_and_put_back():
    """The follower tells each servo its period (item 69) while connected,
    and puts back what the servo had: left to learn it from the frames'
    stamps, a servo under a host's +-10 ms at 60 Hz took steps of 10.75 ms
    for the period, the stream stopped at a late frame, and the horn
    swung at 4 342 deg/s^2 (docs/lerobot.md)."""
    with Simulator(ids=[1, 2], paced=True) as sim:
        with sim.bus() as bus:
            Servo(bus, 2).write("stream_period_ms", 40)  # another program's
            arm = Arm(bus, {"a": 1, "b": 2}, fps=60, watchdog_ms=0).open()
            assert [Servo(bus, i).read("stream_period_ms") for i in (1, 2)] == [17, 17]
            arm.close()
            assert [Servo(bus, i).read("stream_period_ms") for i in (1, 2)] == [0, 40]
