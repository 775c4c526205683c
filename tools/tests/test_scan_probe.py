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
