"""scan.probe listens long enough for every servo at one ID: on a bus of new
servos (all at ID 0) their answers follow one another on the wire, and an
answer still arriving when a window closes is counted as garbled, which
bringup takes for a collision ("connect one new servo at a time")."""
import struct

import pytest

from servoctl import protocol as p
from servoctl import scan, update

BAUD = 115200
BYTE_S = 10 / BAUD


class Wire:
    """Servos that share one ID and answer back to back after the request,
    on a wire timed in bytes: gather() returns the answers that ended within
    its window, and a cut one as stray bytes (as protocol.Bus.gather)."""

    def __init__(self, serials):
        self.serials = serials
        self.serial = type("Port", (), {"baudrate": BAUD})()
        self.windows = {}

    def answer(self, code: int, servo_id: int, serial: int) -> bytes:
        if code == p.PING:
            return bytes([servo_id])
        if code == update.UPDATE_STATUS:
            return bytes([servo_id, update.MODE_APP]) + bytes(14)
        return bytes([servo_id, scan._SERIAL.id]) + struct.pack("<I", serial)

    def gather(self, code: int, content: bytes, window_s: float):
        self.windows[code] = window_s
        t = len(p.request_frame(code, content)) * BYTE_S
        good, stray = [], 0
        for serial in self.serials:
            frame = p.response_frame(code, self.answer(code, content[0], serial))
            ends = t + len(frame) * BYTE_S
            if ends <= window_s:
                good.append(frame[4:-1])
            elif t < window_s:
                stray += round((window_s - t) / BYTE_S)
            t = ends
        return good, 0, stray


@pytest.mark.parametrize("servos", [1, 2, 4, 6])
def test_every_servo_at_one_id_is_heard_whole(servos):
    serials = [0x51A00000 + 0x100 * k for k in range(servos)]
    wire = Wire(serials)
    found = scan.probe(wire, 0, scan.reply_window_s(BAUD))
    assert found.garbled == 0, wire.windows
    assert found.serials == serials and found.serials_complete
    assert found.servos == servos


class SplitAnswer:
    """A port whose one answer arrives in two parts: the first inside the
    window, the rest once the bus clock has passed its end (a busy host
    reads a socket late; a real wire's answer may straddle the end)."""

    def __init__(self, frame: bytes, window_s: float):
        self.baudrate = BAUD
        self.now = 0.0
        self.parts = [(0.001, frame[:4]), (window_s + 0.0005, frame[4:])]

    def clock(self):
        self.now += 0.0002  # each look at the clock, the bus moves on
        return self.now

    def write(self, data):
        return len(data)

    def read(self, _n):
        ready = [d for t, d in self.parts if t <= self.now]
        self.parts = [(t, d) for t, d in self.parts if t > self.now]
        return b"".join(ready)


def test_an_answer_that_straddles_the_window_s_end_is_read_whole():
    window_s = 0.004
    frame = p.response_frame(p.PING, bytes([3]))
    bus = p.Bus("loop://", BAUD)
    port = SplitAnswer(frame, window_s)
    bus.serial, bus._fd, bus.clock = port, None, port.clock
    good, bad, stray = bus.gather(p.PING, bytes([3]), window_s)
    assert (good, bad, stray) == ([bytes([3])], 0, 0)
