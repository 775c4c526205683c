"""The servo's own limits on streamed setpoints,
on servo_sim: raw StreamSetpoint packets, as any host may send them, past
whatever servoctl checks first. With the angle limits on, a setpoint past
them leaves the horn at the limit and the limiter says angle, alone or as
a SyncCommand's record; a setpoint 2000 deg away is reached (it stopped at
1638.5 deg), at no more than the stream's top speed. Time is the
simulator's."""
from servoctl import protocol as p
from servoctl.servo import Servo

# No host paces these setpoints on the wall clock: each carries its own time
# (host_ms) and the test waits on the simulated clock, so the simulator is
# the fixtures' fast one (conftest.py).


def setpoint(bus, servo_id, decideg, velocity=0, host_ms=0):
    bus.send(p.STREAM_SETPOINT, p.encode_request(p.STREAM_SETPOINT, servo_id, decideg, velocity, host_ms))


def sync_setpoints(bus, records, host_ms=0):
    """One SyncCommand of StreamSetpoint records: {id: decideg}."""
    content = bytes([p.STREAM_SETPOINT, 9, len(records)])
    for servo_id, decideg in records.items():
        content += p.encode_request(p.STREAM_SETPOINT, servo_id, decideg, 0, host_ms)
    bus.send(p.SYNC, content)


def settled(sim, servo, timeout_s):
    """Waits (simulated time) until the horn has stopped; its snapshot."""
    sim.wait_until(lambda: abs(servo.read_motion().velocity_decideg_s) < 5
                   and servo.read_motion().flags & servo.read_motion().PROFILE_ENDED, timeout_s)
    sim.sleep(0.2)
    return servo.read_motion()


def test_a_streamed_setpoint_past_the_angle_limit_stops_at_it(sim, bus, servo):
    servo.write("angle_limit_on", 1)
    servo.write("angle_max", 1350)
    setpoint(bus, 1, 3000)  # 300 deg, beyond angle_max
    snap = settled(sim, servo, 3.0)
    assert 1345 <= snap.angle_decideg <= 1352, snap
    assert snap.target_decideg == 1350, snap
    assert snap.limiter == "angle", snap
    sync_setpoints(bus, {1: -3000, 2: 0}, host_ms=20)
    snap = settled(sim, servo, 3.0)
    assert -1352 <= snap.angle_decideg <= -1345, snap
    assert snap.limiter == "angle", snap
    setpoint(bus, 1, 100, host_ms=40)  # within them: nothing holds it back
    snap = settled(sim, servo, 3.0)
    assert abs(snap.angle_decideg - 100) <= 3 and snap.limiter == "none", snap


def test_a_setpoint_2000_deg_away_is_reached(sim, bus, servo):
    servo.write("angle_limit_on", 0)
    start = sim.clock_s()
    setpoint(bus, 1, 20000)
    snap = servo.read_motion()
    assert snap.target_decideg == 20000, snap
    snap = settled(sim, servo, 12.0)
    took = sim.clock_s() - start
    print(f"2000 deg: reached {snap.angle_decideg / 10} deg in {took:.2f} s")
    assert abs(snap.angle_decideg - 20000) <= 5, snap
    assert took >= 2000 / 750, took  # never faster than the stream's top speed


def horn_extremes(sim, servo, seconds):
    """The horn's lowest and highest reading (0.1 deg) over seconds of
    simulated time, read every 10 ms."""
    low = high = servo.read_motion().angle_decideg
    end = sim.clock_s() + seconds
    while sim.clock_s() < end:
        angle = servo.read_motion().angle_decideg
        low, high = min(low, angle), max(high, angle)
        sim.sleep(0.01)
    return low, high


def test_a_streams_path_keeps_within_the_limits_between_setpoints(sim, bus, servo):
    """The factory limits (+-135 deg): a setpoint at the limit whose end
    speed would run on past it (750 deg/s, a period of 1 s learned from the
    stamps: it reached 893 deg), and one whose cubic would bulge past it
    and run on the other way (216 deg, then -470 deg)."""
    servo.write("angle_limit_on", 1)
    setpoint(bus, 1, 0, host_ms=0)
    settled(sim, servo, 2.0)
    setpoint(bus, 1, 1350, velocity=7500, host_ms=1000)
    low, high = horn_extremes(sim, servo, 3.0)
    assert -5 <= low and high <= 1352, (low, high)
    assert servo.read_motion().limiter == "angle"
    setpoint(bus, 1, 1000, host_ms=2000)
    settled(sim, servo, 2.0)
    setpoint(bus, 1, 1350, velocity=-6000, host_ms=3000)
    low, high = horn_extremes(sim, servo, 3.0)
    assert -1352 <= low and high <= 1352, (low, high)
