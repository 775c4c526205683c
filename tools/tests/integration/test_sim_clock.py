"""servoctl given a simulator's control port (--sim-control) waits on the
simulator's clock: a simulator that falls behind the wall clock (a busy PC;
here one stopped for a while, SIGSTOP) is not taken for a servo that does
not answer. Without the control port servoctl waits on the host's clock,
and the same lag is a NoReply."""
import os
import signal
import threading

import pytest

from servoctl.cli import main
from servoctl.sim import Simulator


def _lagging(sim, host_s) -> threading.Timer:
    """The simulator stopped now, for host_s of host time (None: until the
    caller resumes it): its clock stands still while a request is
    outstanding, as on a PC too busy to run it."""
    os.kill(sim.process.pid, signal.SIGSTOP)
    resume = threading.Timer(host_s or 0, os.kill, (sim.process.pid, signal.SIGCONT))
    if host_s is not None:
        resume.start()
    return resume


def _ping_behind(sim, capsys, *options):
    """ping 1 with the simulator stopped: with the control port (options)
    for 0.3 s of host time, its answer then awaited on its clock; without
    it, until the host has given up on its own clock, however long a
    loaded PC takes to run it (resumed by a timer, the simulator could
    answer a host held up that long in time)."""
    resume = _lagging(sim, 0.3 if options else None)
    try:
        rc = main(["--port", sim.url, *options, "ping", "1"])
    finally:
        if options:
            resume.join()
        else:
            os.kill(sim.process.pid, signal.SIGCONT)
    out = capsys.readouterr()
    return rc, out.out + out.err


@pytest.mark.parametrize("board", [None, "stm32f030k6"])
def test_a_lagging_simulator_answers_within_its_own_clocks_timeout(tmp_path, capsys, board):
    """servo_sim and a virtual board alike; scan's windows too, on the
    board."""
    with Simulator(ids=[1], state_dir=str(tmp_path / "state"), board=board) as sim:
        rc, out = _ping_behind(sim, capsys)
        assert rc == 3 and "servo 1: no reply" in out, out  # the host's 100 ms passed
        rc, out = _ping_behind(sim, capsys, "--sim-control", str(sim.control_port))
        assert rc == 0 and "servo 1: answered" in out, out
        resume = _lagging(sim, 0.3)
        try:
            rc = main(["--port", sim.url, "--sim-control", str(sim.control_port), "scan", "--last", "3"])
        finally:
            resume.join()
        out = capsys.readouterr().out
        assert rc == 0 and "servo 1 at 115200 baud" in out and "1 servo(s) found" in out, out
        assert sim.state(1)["collisions"] == 0


def test_sim_prints_both_exports():
    import subprocess
    import sys
    from pathlib import Path

    tools = Path(__file__).resolve().parents[2]
    proc = subprocess.Popen([sys.executable, "-m", "servoctl.cli", "sim", "--tcp", "0"], cwd=tools,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        first, export = proc.stdout.readline(), proc.stdout.readline()
    finally:
        proc.terminate()
        # A guard, not a figure: servoctl gives servo_sim 10 s to stop
        # before it kills it, and a loaded PC slows both (15 s was missed).
        proc.communicate(timeout=60)
    url, control = first.split()[3].rstrip(","), first.split()[5].rsplit(":", 1)[1]
    assert export.split() == ["export", f"SERVOCTL_PORT={url}", f"SERVOCTL_SIM_CONTROL={control}"], export


def test_sim_refuses_tcp_with_link_as_a_usage_error(tmp_path, capsys):
    assert main(["sim", "--tcp", "0", "--link", str(tmp_path / "servo")]) == 2
    assert "not with --tcp" in capsys.readouterr().err


def test_all_bauds_over_a_socket_sweeps_the_simulators_host_rate(tmp_path, capsys):
    """Given the control port, scan --all-bauds sets each rate there
    (hostbaud) and finds a servo at 1 Mbaud; the host rate is put back."""
    with Simulator(ids=[1], state_dir=str(tmp_path / "state"), fast=True) as sim:
        assert main(["--port", sim.url, "config", "set", "1", "baud", "1000000"], clock=sim.clock_s) == 0
        capsys.readouterr()
        assert main(["--port", sim.url, "--sim-control", str(sim.control_port), "scan", "--all-bauds",
                     "--last", "2"], clock=sim.clock_s) == 0
        out = capsys.readouterr()
        assert "servo 1 at 1000000 baud" in out.out, out.out + out.err
        assert sim.state(1)["host_baud"] == 115200  # as it was


def test_ping_of_a_shared_id_says_the_answer_was_garbled(tmp_path, capsys):
    """Three servos at ID 0 answer a Ping at once and garble each other on
    the wire: not "no reply" (exit 3) but what scan would say, exit 1."""
    with Simulator(fast=True, ids=[0, 0, 0], state_dir=str(tmp_path / "state")) as sim:
        rc = main(["--port", sim.url, "ping", "0"], clock=sim.clock_s)
        out = capsys.readouterr().out
        assert rc == 1, out
        assert ("servo 0: garbled answer: two or more servos may share ID 0; see 'servoctl scan'"
                in out), out


def _sent_late(bus, host_late_s: float) -> None:
    """Each request the bus sends held up host_late_s of host time first."""
    import time

    sends = bus.send_burst

    def late(requests):
        time.sleep(host_late_s)
        sends(requests)
    bus.send_burst = late


def _step_record(tmp_path, name: str, host_late_s: float, jam_seed=None) -> list:
    """One of identify's open-loop steps (ReadMotion after ReadMotion, as
    fast as the host goes) on a paced servo_sim, each request sent
    host_late_s of host time late: a host a loaded PC holds up; with
    jam_seed, the simulator held up too (_jammed)."""
    from servoctl.identify import record_step
    from servoctl.servo import Servo

    with Simulator(state_dir=str(tmp_path / name), host_link="raw", paced=True) as sim:
        with sim.bus(timeout=0.2) as bus:
            _sent_late(bus, host_late_s)
            unjam = _jammed(sim, jam_seed) if jam_seed is not None else (lambda: None)
            try:
                step = record_step(Servo(bus, 1), 0.3, 300, sim.sleep)  # then damped to rest: sim.sleep
            finally:
                unjam()
            sim.wait_until(lambda: sim.state(1)["velocity"] == 0.0, 1.0)
            ended = sim.clock_s()
        assert sim.state(1)["collisions"] == 0
    return [(s.t, s.angle, s.current, s.duty) for s in step.samples] + [ended]


def test_a_paced_simulator_sees_the_same_host_whatever_its_speed(tmp_path):
    """Simulator(paced=True) (servo_sim --clock paced) runs only while the
    host waits on it: a host-paced experiment (identify's, test_identify.py)
    records the same samples, to the last bit, from a host that sends each
    request 3 ms late as from one that does not. On a simulator that follows
    the wall clock the late host samples a third as often."""
    on_time = _step_record(tmp_path, "on-time", 0.0)
    assert len(on_time) > 80 and max(abs(s[1]) for s in on_time[:-1]) > 0.2  # it turned (rad)
    assert _step_record(tmp_path, "late", 0.003) == on_time


def _jammed(sim, seed: int):
    """The simulator stopped (SIGSTOP) again and again, up to 3 ms of host
    time each, 3 ms apart at most (seeded), as a loaded PC holds it up at
    moments of its making; until the function returned is called (and
    has it running again)."""
    import random
    import time

    rng, done = random.Random(seed), threading.Event()

    def jam():
        while not done.wait(0.003 * rng.random()):
            os.kill(sim.process.pid, signal.SIGSTOP)
            time.sleep(0.003 * rng.random())
            os.kill(sim.process.pid, signal.SIGCONT)
    thread = threading.Thread(target=jam, daemon=True)
    thread.start()
    return lambda: (done.set(), thread.join())


def test_a_paced_simulator_held_up_by_the_pc_sees_the_same_host(tmp_path):
    """One of identify's steps on a paced servo_sim, the simulator itself
    held up now and then (_jammed): the same samples to the bit. A host
    that had read an answer before the simulator stood still at its end
    said, waiting for its next one, that it had looked at every byte; the
    simulator ran past the answer to where it read the next request, 248 us
    later (identify's play came out 0.3-16.8 % off under load)."""
    on_time = _step_record(tmp_path, "on-time", 0.0)
    for seed in (1, 2):
        assert _step_record(tmp_path, f"jammed-{seed}", 0.0, seed) == on_time


def test_a_paced_host_waiting_for_an_answer_not_begun_tells_nothing(tmp_path):
    """Bytes read before the host's request are the last answer's: while
    none of the next has come (the simulator held up), the host does not
    tell the paced simulator it has looked at them all (the clock file's
    offset 24, read on its way to an answer's end: _host_read)."""
    from servoctl import protocol as p
    from servoctl.servo import Servo

    with Simulator(state_dir=str(tmp_path / "state"), paced=True) as sim:
        with sim.bus(timeout=0.2) as bus:
            Servo(bus, 1).read_motion()
            told = bytes(sim._clock_map[24:32])
            seen = []
            resume = _lagging(sim, None)
            threading.Timer(0.05, lambda: (seen.append(bytes(sim._clock_map[24:32])), resume.run())).start()
            bus.send(p.READ_MOTION, bytes([1]))
            assert bus.read_response(p.READ_MOTION, 1)
            assert seen == [told]


def _monitor_past_a_silent_slot(tmp_path, name: str, host_late_s: float) -> tuple:
    """Sync Monitors of 1, 2, 3 (2 absent) on a paced servo_sim, each sent
    host_late_s of host time late: (who answered, the clock after each)."""
    from servoctl import group

    with Simulator(state_dir=str(tmp_path / name), ids=[1, 3], paced=True) as sim:
        with sim.bus(timeout=0.2) as bus:
            _sent_late(bus, host_late_s)
            seen = []
            for _ in range(3):
                seen.append((sorted(group.sync_monitor(bus, [1, 2, 3])), sim.clock_s()))
    return seen


def test_a_paced_sync_monitor_runs_on_past_an_absent_servos_slot(tmp_path):
    """Servo 2's slot passes in silence and servo 3 answers after it. A
    paced servo_sim stood still once servo 1 had answered, so the host
    waited for 3 (and for the round's end) on a clock that never moved,
    until the stalled-clock error; the host now says it has read all it was
    sent, and the simulator runs on, the same for a late host."""
    on_time = _monitor_past_a_silent_slot(tmp_path, "on-time", 0.0)
    assert [who for who, _ in on_time] == [[1, 3]] * 3
    assert _monitor_past_a_silent_slot(tmp_path, "late", 0.003) == on_time


def _held_up_on_its_way(sim, bus) -> None:
    """Each time the bus tells the paced simulator to run to a later time
    T, it first runs to 0.5 ms before T and is stopped there for 0.1 s of
    host time (SIGSTOP), as a loaded PC holds it up: a host that reads the
    clock then sees it past its deadline (T is 1 ms past it) and not yet
    where the simulator stops."""
    import time

    from servoctl.sim import on_us_grid

    run_ahead = bus.run_ahead

    def held_up(until_s, answer=False):
        on_the_way = on_us_grid(until_s - 0.0005)  # where it stops: no float's hair short
        if sim.clock_s() < on_the_way:
            run_ahead(on_the_way, answer)
            while sim.clock_s() < on_the_way:
                time.sleep(0.0002)
            _lagging(sim, 0.1)  # resumed by its timer
        run_ahead(until_s, answer)
    bus.run_ahead = held_up


@pytest.mark.parametrize("wait", ["read_response", "drain"])
def test_a_paced_wait_ends_where_the_simulator_stops_not_on_its_way(tmp_path, wait):
    """A wait with no answer (servo 2 is absent) ends once the paced clock
    stands where the host told it to stop, however late a loaded PC lets
    it get there: a host that took an event on the way for the end let its
    next request land at a time of the PC's making (a Sync Monitor's
    rounds differed by 0.938 ms under load)."""
    from servoctl import protocol as p
    from servoctl.errors import NoReply
    from servoctl.sim import on_us_grid

    with Simulator(state_dir=str(tmp_path / "state"), ids=[1], paced=True) as sim:
        with sim.bus(timeout=0.02) as bus:
            _held_up_on_its_way(sim, bus)
            start = sim.clock_s()
            if wait == "drain":
                bus.drain()
                end = start + bus._longest_answer_s()
            else:
                bus.send(p.PING, bytes([2]))
                with pytest.raises(NoReply):
                    bus.read_response(p.PING, 2)
                end = start + 0.02
            assert sim.clock_s() == on_us_grid(end + 0.001)
