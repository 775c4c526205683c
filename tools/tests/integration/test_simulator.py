"""The simulator fails the way a real bus fails: a servo at another baud
rate than the host hears nothing, a host that floods the line is held back
by it rather than leaving hours of backlog, and the fault channel refuses
values no model can take."""
import math
import time

import pytest
import serial

from servoctl import protocol as p
from servoctl.protocol import Bus, NoReply, ServoError
from servoctl.servo import Servo
from servoctl.sim import Simulator


@pytest.fixture
def pty_sim(tmp_path):
    with Simulator(fast=True, ids=[1, 2], tcp=False, state_dir=str(tmp_path / "state")) as sim:
        yield sim


def test_a_servo_at_another_baud_rate_is_not_heard(pty_sim):
    with pty_sim.bus(baud=115200) as bus:
        assert Servo(bus, 1).ping() and Servo(bus, 2).ping()
        Servo(bus, 2).write("baud", 7)  # 500000: answered at 115200, then it switches
        pty_sim.sleep(0.05)
        assert Servo(bus, 1).ping()
        with pytest.raises(NoReply):
            bus.request(p.PING, bytes([2]))
    assert pty_sim.state(2)["baud"] == 500000
    with pty_sim.bus(baud=500000) as bus:
        assert Servo(bus, 2).ping()
        with pytest.raises(NoReply):
            bus.request(p.PING, bytes([1]))


def test_a_second_program_on_the_port_is_refused_not_let_in(pty_sim, capsys):
    """servoctl opens the port exclusively. A second servoctl gets
    a one-line 'in use' and exit 4, and the first keeps its answers."""
    from servoctl.cli import main

    with pty_sim.bus() as bus:
        assert main(["--port", pty_sim.url, "ping", "1"]) == 4
        err = capsys.readouterr().err
        assert "in use by another program" in err and len(err.strip().splitlines()) == 1, err
        assert Servo(bus, 1).ping() and Servo(bus, 2).ping()
    assert main(["--port", pty_sim.url, "ping", "1"]) == 0  # free again


@pytest.mark.parametrize("board", [None, "stm32f103"])
def test_a_second_client_of_the_tcp_bus_is_told_it_is_in_use(tmp_path, capsys, board):
    """Watching in one terminal while commanding from another: on the
    simulator's TCP port the second servoctl waited, and said "no reply"
    (exit 3). One client at a time, as on a serial port: the second hears
    the bus is in use (exit 4), the first keeps its answers, and once it
    leaves the next one is served."""
    from servoctl.cli import main
    from servoctl.sim import Simulator

    with Simulator(ids=[1], state_dir=str(tmp_path / "state"), board=board) as sim:
        with sim.bus() as bus:
            assert main(["--port", sim.url, "ping", "1"], clock=sim.clock_s) == 4
            err = capsys.readouterr().err
            assert "is in use by another program" in err and len(err.strip().splitlines()) == 1, err
            assert Servo(bus, 1).ping()
        assert main(["--port", sim.url, "ping", "1"], clock=sim.clock_s) == 0  # free again
        assert main(["--port", sim.url, "ping", "1"], clock=sim.clock_s) == 0  # and again at once


def _one_leaves_as_the_next_comes(sim, next_client):
    """One client sends a Ping and leaves, and the next connects
    (next_client()), while a loaded PC holds the simulator up (SIGSTOP)."""
    import os
    import signal
    import socket

    address = ("127.0.0.1", int(sim.url.rsplit(":", 1)[1]))
    os.kill(sim.process.pid, signal.SIGSTOP)
    try:
        with socket.create_connection(address) as first:
            first.sendall(p.request_frame(p.PING, bytes([1])))
        return next_client(address)
    finally:
        os.kill(sim.process.pid, signal.SIGCONT)


@pytest.mark.parametrize("board", [None, "stm32f103"])
def test_the_next_client_is_served_after_one_that_left_while_the_simulator_was_held_up(tmp_path, board):
    """The simulator reads the first one's last bytes and its leaving
    before it takes the next, which it serves (both told it the bus was in
    use: servoctl's exit 4)."""
    with Simulator(ids=[1], state_dir=str(tmp_path / "state"), board=board) as sim:
        with _one_leaves_as_the_next_comes(sim, lambda _: sim.bus()) as bus:
            assert Servo(bus, 1).ping()


@pytest.mark.parametrize("board", [None, "stm32f103"])
def test_the_next_client_never_hears_the_answer_to_the_one_that_left(tmp_path, board):
    """As above, the next client sending nothing: the Ping's answer is the
    first one's, and it hears nothing of it (before: it did, and one that
    asked the same would take it for its own answer)."""
    import socket

    with Simulator(ids=[1], state_dir=str(tmp_path / "state"), board=board) as sim:
        with _one_leaves_as_the_next_comes(sim, socket.create_connection) as second:
            second.settimeout(0.05)
            heard, start = b"", sim.clock_s()
            while sim.clock_s() - start < 0.05:  # the answer's wire time, many times over
                try:
                    heard += second.recv(256)
                except socket.timeout:
                    pass
            assert heard == b""
        with sim.bus() as bus:  # and the next that talks is answered
            assert Servo(bus, 1).ping()


def test_a_flood_is_held_back_not_queued_for_hours(pty_sim):
    """Two seconds of garbage written as fast as the pty takes it: at
    115200 baud the line carries about 23 kB of it; the rest waits in the
    writer. Once the writer stops, the bus is usable within a second or two
    (it used to owe the wire time of every byte it had dropped)."""
    port = serial.Serial(pty_sim.url, 115200, write_timeout=0.05)
    sent = 0
    deadline = time.monotonic() + 2.0
    junk = bytes(range(256)) * 16
    while time.monotonic() < deadline:
        try:
            sent += port.write(junk)
        except serial.SerialTimeoutException:
            pass
    port.reset_output_buffer()
    port.close()
    with pty_sim.bus(baud=115200, timeout=0.2) as bus:
        def answers():
            try:
                bus.request(p.PING, bytes([1]))
                return True
            except ServoError:
                return False

        waited = pty_sim.wait_until(answers, 5.0)  # simulated seconds
    print(f"flood: {sent} bytes accepted in 2 s; bus answering {waited:.2f} s after")
    assert pty_sim.state(1)["collisions"] == 0


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "1e300", "-1e300"])
def test_the_fault_channel_refuses_what_no_model_can_take(sim, value):
    for command in ("supply", "load", "ambient", "soak", "stop"):
        with pytest.raises(ServoError, match=f"{command} takes"):
            sim.control(f"{command} {value}")
    state = sim.state(1)
    for key in ("angle", "velocity", "current", "winding", "case", "supply"):
        assert math.isfinite(state[key]), key
    with sim.bus() as bus:
        assert Servo(bus, 1).ping()


def test_a_request_the_moment_the_simulator_is_ready_finds_the_readings_taken(tmp_path):
    """servo_sim says ready once its servos have run their first control
    ticks, as a host meets a servo after its power-up. The request here
    reaches the simulator while it is stopped at that moment (a busy PC), so
    it lands on the bus at the simulated instant of ready: the supply (ID 1)
    has been read by then, not 0 mV."""
    import os
    import signal
    import socket

    with Simulator(fast=True, ids=[1], state_dir=str(tmp_path / "state")) as sim:
        host, port = sim.url.removeprefix("socket://").split(":")
        with socket.create_connection((host, int(port))) as link:
            os.kill(sim.process.pid, signal.SIGSTOP)
            try:
                link.sendall(p.request_frame(p.READ_DATA, bytes([1, 1])))
                time.sleep(0.05)
            finally:
                os.kill(sim.process.pid, signal.SIGCONT)
            link.settimeout(5.0)  # a bound on a hung simulator, not a judgement of time
            answer = b""
            while len(answer) < 8:
                answer += link.recv(64)
    assert answer[:6] == p.response_frame(p.READ_DATA, bytes([1, 1, 0, 0]))[:6]
    voltage_mv = int.from_bytes(answer[6:8], "little")
    assert 7300 <= voltage_mv <= 7500, f"the supply read {voltage_mv} mV"


def test_the_published_clock_is_the_control_ports_read_without_asking(sim):
    """servo_sim's clock file (sim_clock.h) is what "clock" answers, and
    reading it opens no control connection: a host that reads the clock
    at every answer spends no simulated time on round trips."""
    assert sim._clock_map is not None, "servo_sim published no clock file"
    readings = [sim.clock_s() for _ in range(1000)]
    assert readings == sorted(readings) and readings[-1] > 0
    assert sim._clock_conn is None, "the clock was asked for on the control port"
    for _ in range(20):
        before = sim.clock_s()
        asked = float(sim.control("clock").split()[0].split("=")[1]) / 1000
        after = sim.clock_s()
        assert before <= asked <= after
    sim.sleep(0.05)  # waits on the mapped clock
    assert sim.clock_s() - readings[-1] >= 0.05


def test_the_clock_file_goes_when_the_simulator_stops(tmp_path):
    state = tmp_path / "state"
    with Simulator(fast=True, ids=[1], state_dir=str(state)):
        assert (state / "bus.clock").stat().st_size == 32  # the clock, the host's wait, its bytes sent and read
    assert not (state / "bus.clock").exists()
