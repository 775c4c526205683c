"""What the robot-loop benchmarks share (scripts/stream_bench.sh,
scripts/c_loop_bench.sh): simulated servos at a baud rate, and the gaps of
a cycle on the simulator's wire log. Run with the project's .venv, from
the repository (servoctl importable)."""
import contextlib
import tempfile

from servoctl import registers
from servoctl.servo import Servo
from servoctl.sim import Simulator


@contextlib.contextmanager
def at_baud(ids, baud, host_link=None, nice=None, paced=False):
    """Simulated servos at baud, soft start off; stopped whatever happens.
    nice: the simulator's niceness (below 0 needs root; else as started);
    paced: its clock moves only while the host waits (servo_sim --clock
    paced), so the host's own time and the PC's load are not in the figure."""
    with Simulator(ids=ids, state_dir=tempfile.mkdtemp(prefix="stream-bench-"), host_link=host_link,
                   nice=nice, paced=paced) as sim:
        set_up(sim, ids, baud)
        yield sim


def set_up(sim, ids, baud):
    code = {rate: c for c, rate in registers.BAUD_RATES.items()}[baud]
    with sim.bus() as bus:
        for i in ids:
            Servo(bus, i).write("soft_start_on", 0)
            if baud != 115200:
                Servo(bus, i).write("baud", code)  # answered at 115200, then it switches
    if baud != 115200:
        sim.control(f"hostbaud {baud}")
        sim.sleep(0.05)


def cycle_gaps(sim):
    """Mean gaps of the latest cycles on the simulator's wire log, in us:
    an answer's end to the host's next burst, the burst's end to the
    first answer, an answer's end to the next."""
    spans = [line.split() for line in sim.control("wire 1024").splitlines() if line != "end"]
    gaps = {"host": [], "first": [], "between": []}
    for (_, end, _, before), (start, _, _, sender) in zip(spans, spans[1:]):
        kind = "host" if sender == "host" else "first" if before == "host" else "between"
        gaps[kind].append(int(start) - int(end))
    return [sum(g) / len(g) for g in gaps.values()]
