"""The servo's own limits on streamed setpoints on both virtual boards, the
shipped images as flashed: with the angle limits on (135 deg), a streamed
setpoint of 300 deg leaves the horn at the limit and the limiter says
angle; a setpoint 2000 deg away is planned to the end (it stopped at
1638.5 deg) at no more than the stream's top speed. Time is the boards'
simulated time, run ahead while the test waits on it (fast): the setpoints
carry their own times (host_ms), no host paces them on the wall clock."""
import pytest

from servoctl import protocol as p
from servoctl.servo import Servo
from servoctl.sim import Simulator

from ..scheduled import LEAD_S, schedule
from .test_virtual_boards import BOARDS, finish


@pytest.fixture(params=BOARDS)
def one(request, tmp_path):
    sim = Simulator(ids=(1,), tcp=True, state_dir=str(tmp_path / "state"), board=request.param,
                    fast=True).start()
    try:
        with sim.bus(timeout=0.3) as bus:
            servo = Servo(bus, 1)
            servo.write("soft_start_on", 0)
            yield sim, bus, servo
    finally:
        finish(sim, [1])


def setpoint_frame(decideg, host_ms=0, velocity=0) -> bytes:
    return p.request_frame(p.STREAM_SETPOINT, p.encode_request(p.STREAM_SETPOINT, 1, decideg, velocity, host_ms))


def setpoint(bus, decideg, host_ms=0, velocity=0):
    bus.send(p.STREAM_SETPOINT, p.encode_request(p.STREAM_SETPOINT, 1, decideg, velocity, host_ms))


def test_a_streamed_setpoint_keeps_to_the_limits(one):
    sim, bus, servo = one
    servo.write("angle_limit_on", 1)
    servo.write("angle_max", 1350)
    setpoint(bus, 3000)
    sim.wait_until(lambda: servo.read_motion().flags & servo.read_motion().PROFILE_ENDED, 3.0)
    sim.sleep(0.4)
    snap = servo.read_motion()
    assert 1345 <= snap.angle_decideg <= 1352, snap
    assert snap.limiter == "angle", snap
    servo.write("angle_limit_on", 0)
    setpoint(bus, 20000, host_ms=20)
    start = servo.read_motion()
    assert start.target_decideg == 20000, start
    sim.sleep(0.5)
    later = servo.read_motion()
    speed = (later.setpoint_decideg - start.setpoint_decideg) / 10 / later.seconds_since(start)
    assert 0 < speed <= 750.5, speed


def test_a_streams_path_keeps_within_the_limits_between_setpoints(one):
    """A setpoint at the factory limit (135 deg) whose end speed, 750 deg/s
    over a learned 1 s period, ran on to 890 deg on both boards. The two
    setpoints land a second apart on the simulated wire (hostsend): a host
    that a loaded PC runs late made the second land late."""
    sim, bus, servo = one
    servo.write("angle_limit_on", 1)
    first = sim.clock_s() + LEAD_S
    schedule(sim, [(first, setpoint_frame(0)), (first + 1.0, setpoint_frame(1350, 1000, 7500))])
    sim.sleep(first + 1.0 - sim.clock_s())
    # The horn as the model has it (the control port): reads on the bus
    # would land at times a loaded PC sets, and move the ticks they share
    # the CPU with.
    high = sim.state(1)["angle"]
    end = sim.clock_s() + 3.0
    while sim.clock_s() < end:
        high = max(high, sim.state(1)["angle"])
        sim.sleep(0.01)
    assert high <= 135.2, high
    assert servo.read_motion().limiter == "angle"
