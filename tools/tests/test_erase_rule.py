"""servoctl's rule for a request that lands in a servo's page erase,
carried out but not answered (docs/decisions-hardware.md): a read is sent
once more, a write read back, and what cannot be read back is reported with
ReadStore's count. A bus whose servo drops the answers it is told to: no
simulator needed."""
import struct

import pytest

from servoctl import protocol as p
from servoctl import registers
from servoctl.servo import Servo


class ErasingBus(p.Bus):
    """Servo 1 on a bus that carries out every request and leaves the next
    `drop` answers unsent, as during an erase (counted as ReadStore does)."""

    def __init__(self, drop=0):  # no port
        self.timeout, self.sent_again, self.drop = 0.1, 0, drop
        self.values = {"current_limit": 3000, "baud": 5}
        self.dropped, self.answer, self.sent = 0, None, []

    def send(self, code, content):
        self.sent.append(code)
        answer = self._carry_out(code, content)
        if self.drop:
            self.drop -= 1
            self.dropped += 1
            answer = None
        self.answer = (code, answer)

    def _carry_out(self, code, content):
        if code == p.READ_DATA:
            item = registers.find(content[1])
            return content[:2] + item.pack(self.values[item.name])
        if code == p.WRITE_DATA:
            item = registers.find(content[1])
            self.values[item.name] = item.unpack(content[2:])
            return content[:2] + b"\x01"
        if code == p.READ_STORE:
            fmt = p._SCHEMA.answer_format(p.READ_STORE)
            return struct.pack(fmt, 1, 0, 1, 0, 10000, 1000, 0, 0, self.dropped, 0)
        return bytes([content[0]])  # Ping

    def read_response(self, code, servo_id, timeout=None, deadline=None):
        sent, answer = self.answer
        self.answer = (None, None)
        if sent != code or answer is None:
            raise p.NoReply(f"servo {servo_id}: no reply to packet {code} within 100 ms")
        return answer


def test_a_read_without_an_answer_is_sent_once_more():
    bus = ErasingBus(drop=1)
    assert Servo(bus, 1).read("current_limit") == 3000
    assert bus.sent == [p.READ_DATA, p.READ_DATA] and bus.sent_again == 1
    bus = ErasingBus(drop=2)  # a servo that stays silent: once more only
    with pytest.raises(p.NoReply):
        Servo(bus, 1).read("current_limit")
    assert bus.sent == [p.READ_DATA, p.READ_DATA]


def test_a_write_without_an_answer_is_read_back_not_sent_again():
    bus = ErasingBus(drop=1)
    Servo(bus, 1).write("current_limit", 3001)  # no error: the read shows it taken
    assert bus.sent == [p.WRITE_DATA, p.READ_DATA] and bus.values["current_limit"] == 3001
    bus = ErasingBus(drop=3)  # the read unanswered twice too: the write's own error
    with pytest.raises(p.NoReply, match="no reply to packet 4"):
        Servo(bus, 1).write("current_limit", 3001)


def test_a_write_that_cannot_be_read_back_reports_readstores_count():
    bus = ErasingBus(drop=1)
    with pytest.raises(p.NoReply, match="counts 1 request.s. carried out during a page erase"):
        Servo(bus, 1).write("baud", 8)
    assert bus.sent == [p.WRITE_DATA, p.READ_STORE]  # not sent again
