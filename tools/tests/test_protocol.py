"""servoctl's framing, error reporting and data table, without a servo."""
import pytest

from servoctl import protocol as p
from servoctl import registers
from servoctl.protocol import Bus, BadChecksum, NoReply, UsageError, ValueOutOfRange


def test_frames():
    assert p.request_frame(1, bytes([1])) == bytes.fromhex("124c01010161")
    assert p.response_frame(1, bytes([0])) == bytes.fromhex("051c01010023")
    long = p.request_frame(25, bytes(300))
    assert long[3] == 0xFF and long[4:6] == (300).to_bytes(2, "little")
    assert sum(long[:-1]) % 256 == long[-1]


def test_no_reply_says_who_and_what():
    with Bus("loop://", timeout=0.05) as bus:
        with pytest.raises(NoReply, match="servo 3: no reply to packet 1 within 50 ms"):
            bus.request(p.PING, bytes([3]))  # loop:// echoes the request: not a response


def test_bad_checksum_is_reported():
    with Bus("loop://", timeout=0.05) as bus:
        frame = bytearray(p.response_frame(p.PING, bytes([3])))
        frame[-1] ^= 0x55
        bus.serial.write(bytes(frame))
        with pytest.raises(BadChecksum, match="servo 3: response to packet 1 had a bad checksum"):
            bus.read_response(p.PING, 3)


def test_other_frames_are_skipped():
    with Bus("loop://", timeout=0.05) as bus:
        bus.serial.write(b"\x00\x12" + p.response_frame(p.PING, bytes([4])) +
                         p.response_frame(p.READ_ANGLE, bytes([3, 1, 2])))
        assert bus.read_response(p.READ_ANGLE, 3) == bytes([3, 1, 2])


def test_values_are_checked_before_sending():
    with pytest.raises(ValueOutOfRange, match=r"angle_max \(51\) must be -1800..1800"):
        registers.find("angle_max").check(2000)
    with pytest.raises(ValueOutOfRange, match="read-only"):
        registers.find(1).check(5)
    with pytest.raises(ValueOutOfRange, match="no data item"):
        registers.find("colour")
    values = {i.name: i.default for i in registers.USER}
    block = registers.encode_user_area(values)
    assert len(block) == 32 and registers.decode_user_area(block) == values
    values["low_voltage"] = 9000
    with pytest.raises(ValueOutOfRange, match="below high_voltage"):
        registers.encode_user_area(values)


def test_an_answer_that_arrived_by_the_deadline_is_read_whole():
    """A host that runs late finds its deadline passed with the answer
    already waiting: the last look reads all of it. Over socket://,
    pyserial's in_waiting says 1 whatever is waiting, and reading only
    that lost a 6-byte answer (a scan on a busy machine found nothing)."""
    import itertools
    import socket
    import time

    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen(1)
        late = itertools.chain([0.0], itertools.repeat(1.0))  # past the deadline at once
        with Bus(f"socket://127.0.0.1:{server.getsockname()[1]}", timeout=0.004,
                 clock=lambda: next(late)) as bus:
            peer, _ = server.accept()
            with peer:
                peer.sendall(p.response_frame(p.PING, bytes([1])))
                time.sleep(0.05)  # on the host's socket before the bus looks
                assert bus.read_response(p.PING, 1) == bytes([1])


@pytest.mark.parametrize("port", ["socket://127.0.0.1", "socket://127.0.0.1:abc", "socket://:5000",
                                  "socket://localhost:0", "sockt://127.0.0.1:5000", "rfc2217://"])
def test_a_malformed_port_is_servoctls_usage_error(port, capsys):
    """pyserial said "'<=' not supported between instances of 'int' and
    'NoneType'" (exit 4, a link failure): servoctl names the forms it
    takes, exit 2, nothing opened."""
    from servoctl.cli import main

    assert main(["--port", port, "ping", "1"]) == 2
    err = capsys.readouterr().err
    assert "socket://HOST:PORT" in err and "/dev/ttyUSB0" in err and "not supported" not in err, err
    with pytest.raises(UsageError):
        Bus(port)
