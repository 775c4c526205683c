"""What a stream and a robot's loop put on the wire, byte for byte, and a
simulator's socket read and written directly (protocol.Bus): no servo
needed."""
import socket
import threading

import pytest

from servoctl import protocol as p
from servoctl.protocol import LinkError, NoReply
from servoctl.stream import Limits, RobotLoop, Stream


class RecordingBus:
    """Takes the requests; answers none of them."""

    def __init__(self):
        self.bursts = []
        self.stamp_arrivals = True
        self.serial = type("Port", (), {"baudrate": 1000000})()

    def clock(self):
        return 0.0

    def send_burst(self, requests):
        self.bursts.append(list(requests))

    def read_response(self, code, servo_id, timeout=None, deadline=None):
        raise NoReply("nobody here")


def test_the_robot_loop_sends_its_setpoints_and_sync_monitor_in_one_write():
    """One write a cycle: a host descheduled between two writes would leave
    a gap on the wire between the setpoints and the Sync Monitor."""
    bus = RecordingBus()
    loop = RobotLoop(bus, [1, 2, 3], 0.02, limits={i: Limits() for i in (1, 2, 3)})
    assert loop.cycle({1: 1.0, 2: 2.0, 3: 3.0}) == {}
    assert loop.missed == 3
    [(setpoints, monitor)] = bus.bursts
    assert setpoints[0] == p.SYNC and setpoints[1][:3] == bytes([p.STREAM_SETPOINT, 9, 3])
    assert monitor == (p.SYNC, bytes([p.MONITOR, 1, 3, 1, 2, 3]))


@pytest.mark.parametrize("ids", [[7], [1, 2, 3, 4, 5, 6]])
def test_a_streams_records_are_the_schemas_request(ids):
    """The records packed at once are what encode_request lays out one by one."""
    stream = Stream(RecordingBus(), ids, 0.02, limits={i: Limits() for i in ids})
    stream.sent = 3
    code, content = stream.frame_content({i: 1.5 * i for i in ids}, {i: -2.0 * i for i in ids})
    records = [p.encode_request(p.STREAM_SETPOINT, i, 15 * i, -20 * i, 60) for i in ids]
    if len(ids) == 1:
        assert (code, content) == (p.STREAM_SETPOINT, records[0])
    else:
        assert (code, content) == (p.SYNC, bytes([p.STREAM_SETPOINT, 9, len(ids)]) + b"".join(records))


def test_a_socket_closed_by_the_simulator_is_a_link_error():
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(1)
    got = []

    def serve():
        peer, _ = server.accept()
        with peer:
            got.append(peer.recv(64))
            peer.sendall(p.response_frame(p.PING, bytes([4])))
            got.append(peer.recv(64))  # the second request; then the connection goes

    worker = threading.Thread(target=serve, daemon=True)
    worker.start()
    try:
        with p.Bus(f"socket://127.0.0.1:{server.getsockname()[1]}", timeout=2.0) as bus:
            assert bus.request(p.PING, bytes([4])) == bytes([4])
            with pytest.raises(LinkError, match="closed the connection"):
                bus.request(p.PING, bytes([4]))
    finally:
        worker.join(5)
        server.close()
    assert got == [p.request_frame(p.PING, bytes([4]))] * 2


def test_a_socket_that_takes_no_bytes_is_a_link_error_not_a_hang(monkeypatch):
    """A peer that stops reading (a hung simulator): the write gives up
    after WRITE_STALL_S of host time without a byte taken."""
    monkeypatch.setattr(p, "WRITE_STALL_S", 0.3)
    server = socket.socket()
    server.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    server.bind(("127.0.0.1", 0))
    server.listen(1)
    try:
        with p.Bus(f"socket://127.0.0.1:{server.getsockname()[1]}", timeout=0.1) as bus:
            peer, _ = server.accept()  # never read
            with peer:
                ping = (p.PING, bytes([1]))
                with pytest.raises(LinkError, match="nothing was taken for 0.3 s"):
                    for _ in range(100):  # each burst 60 kB: the buffers fill in a few
                        bus.send_burst([ping] * 10000)
    finally:
        server.close()


def test_the_period_against_the_bus_watchdog():
    """A stream feeds a servo's watchdog once a period: at most half its
    watchdog_ms is taken (a cycle a period late still feeds it), longer is
    refused naming what to do; a watchdog off (0) takes any period."""
    assert Limits(watchdog_ms=100).check_period(3, 50) == ""
    why = Limits(watchdog_ms=100).check_period(3, 51)
    assert "servo 3's bus watchdog (watchdog_ms 100 ms)" in why and "at most 50 ms" in why
    assert "'servoctl config set 3 watchdog_ms 102'" in why
    assert Limits().check_period(3, 1000) == ""
    assert Limits.of({"angle_limit_on": 0, "watchdog_ms": 40}) == Limits(watchdog_ms=40)


def test_a_stream_sent_late_fails_with_its_rate(capsys):
    """servoctl stream's verdict (cli/cmd_stream.py's _verdict): cycles below 0.95 of the
    file's rate were sent late, exit 1 with the rate run, even where every
    servo followed what it got; --report-only exits 0."""
    from servoctl.loop_rate import LoopRate
    from servoctl.cli.cmd_stream import _verdict
    from servoctl.stream import StreamReport

    def report(cycles):
        return StreamReport(0.02, 101, {1: 0.2}, {1: 0.5}, LoopRate(cycles, 2.0, 260.0), 0)

    assert _verdict(report(96), 1.0, False) == 0  # 48 Hz: within 0.95 of 50
    assert _verdict(report(80), 1.0, False) == 1
    assert "went out at 40.0 Hz against the file's 50 Hz" in capsys.readouterr().err
    assert _verdict(report(80), 1.0, True) == 0
    # On a simulator slower than real time the shortfall is named as its.
    slow = StreamReport(0.02, 101, {1: 0.2}, {1: 0.5}, LoopRate(80, 2.0, 260.0), 0, sim_speed=0.62)
    assert _verdict(slow, 1.0, False) == 1
    err = capsys.readouterr().err
    assert "on a simulator that ran at 0.62x real time" in err and "host" not in err, err
    on_time_sim = StreamReport(0.02, 101, {1: 0.2}, {1: 0.5}, LoopRate(80, 2.0, 260.0), 0, sim_speed=1.0)
    assert _verdict(on_time_sim, 1.0, False) == 1
    assert "the host sent them late" in capsys.readouterr().err
    # On a paced simulator the PC's time is nobody's: the cycle's own length is the reason.
    paced = StreamReport(0.0095, 101, {1: 0.2}, {1: 0.5}, LoopRate(90, 1.0, 105.7), 0, paced=True)
    assert _verdict(paced, 1.0, False) == 1
    err = capsys.readouterr().err
    assert "a cycle took 11.11 ms of the paced simulator's time" in err and "host sent" not in err, err
