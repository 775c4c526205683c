"""A simulator the PC kept waiting falls behind the wall clock and catches
up at full speed, but not while its host takes its turn (it has been handed
an answer and the wire is quiet): the host's reaction takes real time, and
the wire's log (on the simulated clock) shows it as it was, not stretched
by the simulator's catching up (firmware/boards/host_sim/main.c,
host_turn_bound). A 16-servo robot loop, whose rounds the sanitised
simulator runs slower than real time, had 0.25-1 ms of host gap a cycle
so, and reached 0.84 of the wire (scripts/c_loop_bench.sh). And a host's
bytes go on the wire at the time it wrote them, not at the bus time the
simulator last ran to before it slept (host_bytes_at)."""
import os
import select
import signal
import socket
import time

from servoctl import protocol as p
from servoctl.sim import Simulator

from .conftest import finish
from .test_bus_timing import wire_spans

PING_ANSWER = 6  # bytes: header 2, code, size, ID, checksum
HOST_TURN_S = 0.005  # how long this host takes to answer, in real time
PINGS = 60  # the original took one in ten or so at 0-2 us


def answer(conn):
    got = b""
    while len(got) < PING_ANSWER:
        ready, _, _ = select.select([conn], [], [], 5.0)
        assert ready, f"no answer: {got!r}"
        chunk = conn.recv(64)
        assert chunk, "the simulator closed the connection"
        got += chunk
    return got


def connect(sim):
    """A real-time host's connection to the simulator's bus (no Nagle delay)."""
    host, port = sim.url.removeprefix("socket://").rsplit(":", 1)
    conn = socket.create_connection((host, int(port)), timeout=5.0)
    conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return conn


def host_gaps(spans):
    """Each host burst's start less the end of the answer before it, us."""
    return [spans[k][0] - spans[k - 1][1] for k in range(1, len(spans)) if spans[k][3] == "host"]


def test_a_host_takes_the_time_it_took(tmp_path):
    """A simulator asleep when the host's bytes came put them on the wire at
    the bus time it had run to before it slept: a host answering at once
    in 0-2 us, faster than the loopback's own round trip (6 us both ends
    awake)."""
    sim = Simulator(ids=[1], host_link="raw", state_dir=str(tmp_path / "state")).start()
    try:
        ping = p.request_frame(p.PING, bytes([1]))
        with connect(sim) as conn:
            for _ in range(PINGS):
                conn.sendall(ping)
                answer(conn)
        gaps = host_gaps(wire_spans(sim))
    finally:
        finish(sim, [1])
    assert len(gaps) == PINGS - 1
    assert min(gaps) >= 3, gaps


def test_a_late_simulator_does_not_charge_its_host_for_catching_up(tmp_path):
    sim = Simulator(ids=[1], host_link="raw", state_dir=str(tmp_path / "state")).start()
    try:
        ping = p.request_frame(p.PING, bytes([1]))
        with connect(sim) as conn:
            os.kill(sim.process.pid, signal.SIGSTOP)  # a PC that keeps the simulator waiting
            try:
                conn.sendall(ping)
                time.sleep(0.3)
            finally:
                os.kill(sim.process.pid, signal.SIGCONT)
            answer(conn)  # the simulator is some 300 ms behind the wall clock now
            time.sleep(HOST_TURN_S)
            conn.sendall(ping)
            answer(conn)
        spans = wire_spans(sim)
    finally:
        finish(sim, [1])
    gaps = host_gaps(spans)
    assert len(gaps) == 1, spans
    gap_us = gaps[0]
    # The host's 5 ms, and what the PC adds to it; caught up meanwhile at
    # full speed, the bus clock ran on by some 100-300 ms.
    assert gap_us < 30000, f"the host's turn took {gap_us} us of the simulated clock"
