"""Fixtures: the firmware on simulated servos (servo_sim from the host
build) and servoctl's bus to it. Every test checks at the end that no two
servos ever talked over each other.

Time in these tests is the simulator's (sim.sleep, sim.wait_until, the
sim_ms and last_move_ms of sim.state): it falls behind the wall clock on a
busy machine, and a test that judged host time would fail there.

The simulator of the sim and sim3 fixtures is fast (Simulator(fast=True)):
its clock runs as fast as it can while the test waits on it, and follows
the wall clock otherwise. A module whose test paces the host on the wall
clock (streams at a rate, loops that time.sleep) sets REAL_TIME = True:
its simulator then only follows the wall clock. One whose host paces the
servos on the simulated clock alone (servoctl stream: bus.sleep) sets
PACED = True: its simulator runs only while the host waits on it
(Simulator(paced=True)), so a loaded PC cannot make the host late."""
import pytest

from servoctl.protocol import Bus
from servoctl.servo import Servo
from servoctl.sim import Simulator


def _start(tmp_path, ids, tcp=True, fast=True, paced=False):
    sim = Simulator(ids=ids, tcp=tcp, state_dir=str(tmp_path / "state"), fast=fast and not paced, paced=paced)
    sim.start()
    return sim


def finish(sim, ids):
    """Stops the simulator whatever happens, then judges what it said."""
    try:
        state = sim.state(ids[0])
    finally:
        err = sim.stop()
    assert state["collisions"] == 0, f"responses collided on the bus: {err}"
    # A real-time simulator that fell far behind would stretch every move.
    assert state["dropped_ticks"] == 0, f"the simulator dropped {state['dropped_ticks']} ticks"
    assert "runtime error" not in err and "AddressSanitizer" not in err, err


def _fast(request) -> bool:
    return not getattr(request.module, "REAL_TIME", False)


def _paced(request) -> bool:
    return getattr(request.module, "PACED", False)


@pytest.fixture
def sim(tmp_path, request):
    s = _start(tmp_path, [1], fast=_fast(request), paced=_paced(request))
    yield s
    finish(s, [1])


@pytest.fixture
def sim3(tmp_path, request):
    s = _start(tmp_path, [1, 2, 3], fast=_fast(request), paced=_paced(request))
    yield s
    finish(s, [1, 2, 3])


@pytest.fixture
def bus(sim):
    with sim.bus(timeout=0.2) as b:
        yield b


@pytest.fixture
def servo(bus):
    s = Servo(bus, 1)
    s.write("soft_start_on", 0)
    return s


