"""servo_sim in real time keeps the wall clock's pace while a host takes
turns of 20-45 ms (reads, a stream's cycles): each pass of its loop in the
host's turn slept its 250 us step and more and then moved the bus clock a
step at most, so it ran at 0.79-0.85 of real time, and a stream stamped on
the host's clock fell 35 deg behind at 30 Hz (docs/simulator.md). This is
the one figure here that is the wall clock's own: it is marked wall_clock
and runs alone."""
import time

import pytest

from servoctl.protocol import Bus
from servoctl.servo import Servo
from servoctl.sim import Simulator

pytestmark = pytest.mark.wall_clock

RUN_S = 1.5
# A loaded PC delays the host's turns, not the simulator's clock: it
# catches up at once whenever it is a step behind, so only a stall at the
# very end of the run (over 150 ms) reads below this. Before: 0.79-0.85.
KEEPS_PACE = 0.9


@pytest.mark.parametrize("turn_ms", [20, 33])
def test_the_simulated_clock_keeps_the_wall_clock_s_pace_between_a_host_s_reads(turn_ms):
    with Simulator(ids=[1]) as sim, Bus(sim.url) as bus:  # the host on the wall clock
        servo = Servo(bus, 1)
        servo.read("voltage")
        sim_start, wall_start = sim.clock_s(), time.monotonic()
        due = wall_start
        while time.monotonic() - wall_start < RUN_S:
            servo.read("voltage")
            due += turn_ms / 1000
            time.sleep(max(0.0, due - time.monotonic()))
        pace = (sim.clock_s() - sim_start) / (time.monotonic() - wall_start)
        assert pace > KEEPS_PACE, f"the simulator ran at {pace:.3f} x real time"
