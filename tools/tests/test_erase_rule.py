"""servoctl's rule for a request that lands in a servo's page erase,
carried out but not answered (docs/decisions-hardware.md): a read is sent
once more, a write read back, and what cannot be read back is reported with
ReadStore's count. A bus whose servo drops the answers it is told to: no
simulator needed."""
import struct

import pytest

from servoctl import protocol as p
from servoctl import registers
from servoctl.servo import Refused, Servo


class ErasingBus(p.Bus):
    """Servos on a bus (servo 1 alone unless told): each carries out every
    request and the next `drop` answers are left unsent, as during an erase
    (counted as ReadStore does); the next `lose` writes are neither carried
    out nor answered (lost on the line). A write of an item in `refuse` is
    refused (answer 0, nothing written)."""

    def __init__(self, drop=0, lose=0, refuse=(), others=None):  # no port
        self.timeout, self.sent_again, self.drop, self.lose = 0.1, 0, drop, lose
        self.servos = {1: {"current_limit": 3000, "baud": 5, "servo_id": 1, "serial": 0x51A00001,
                           "faults": 1}}
        self.servos.update(others or {})
        self.refuse = set(refuse)
        self.dropped, self.answer, self.sent = 0, None, []

    @property
    def values(self):
        return self.servos[1]

    def send(self, code, content):
        self.sent.append(code)
        if self.lose and code in (p.WRITE_DATA, p.WRITE_BATCH, p.CLEAR_FAULTS):
            self.lose -= 1
            self.answer = (code, None)
            return
        answer = self._carry_out(code, content) if content[0] in self.servos else None
        if self.drop and answer is not None:
            self.drop -= 1
            self.dropped += 1
            answer = None
        self.answer = (code, answer)

    def _carry_out(self, code, content):
        values = self.servos[content[0]]
        if code == p.READ_DATA:
            item = registers.find(content[1])
            return content[:2] + item.pack(values[item.name])
        if code == p.WRITE_DATA:
            item = registers.find(content[1])
            if item.name in self.refuse:
                return content[:2] + b"\x00"
            values[item.name] = item.unpack(content[2:])
            if item.name == "servo_id":
                self.servos[values["servo_id"]] = self.servos.pop(content[0])
            return content[:2] + b"\x01"
        if code == p.CLEAR_FAULTS:
            values["faults"] = 0
            return content[:1] + b"\x01"
        if code == p.READ_FAULTS:
            fmt = p._codec._SCHEMA.answer_format(p.READ_FAULTS)
            n = values["faults"]
            return struct.pack(fmt, content[0], n, 0, n, 0, 0, 0, 0, 0, 0, 0, 2 if n else 0)
        if code == p.READ_STORE:
            fmt = p._codec._SCHEMA.answer_format(p.READ_STORE)
            return struct.pack(fmt, content[0], 0, 1, 0, 10000, 1000, 0, 0, self.dropped, 0)
        return bytes([content[0]])  # Ping

    def drain(self):  # a late answer is dropped before a request is sent again
        self.drained = getattr(self, "drained", 0) + 1
        self.late, self.answer = None, (None, None)

    def read_response(self, code, servo_id, timeout=None, deadline=None, item=None):
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


def test_a_lost_write_read_back_not_taken_is_sent_again_and_its_answer_counts():
    bus = ErasingBus(lose=1)  # the write never reached the servo: sent again
    Servo(bus, 1).write("current_limit", 3001)
    assert bus.sent == [p.WRITE_DATA, p.READ_DATA, p.WRITE_DATA] and bus.values["current_limit"] == 3001
    bus = ErasingBus(lose=1, refuse={"current_limit"})  # sent again and refused: an error
    with pytest.raises(Refused):
        Servo(bus, 1).write("current_limit", 3001)
    assert bus.sent[:3] == [p.WRITE_DATA, p.READ_DATA, p.WRITE_DATA]


def test_a_lost_id_change_is_read_back_at_the_new_id_and_sent_again():
    bus = ErasingBus(lose=1)
    Servo(bus, 1).write("servo_id", 3)
    assert sorted(bus.servos) == [3] and bus.sent.count(p.WRITE_DATA) == 2


def test_an_absent_servo_is_not_taken_for_the_one_already_at_the_new_id():
    other = {"current_limit": 3000, "baud": 5, "servo_id": 2, "serial": 0x51A00002, "faults": 0}
    bus = ErasingBus(others={2: other})
    with pytest.raises(p.NoReply):
        Servo(bus, 7).write("servo_id", 2)
    bus = ErasingBus(lose=1, others={2: other})  # lost: read back finds servo 2, not servo 1
    Servo(bus, 1).write("servo_id", 2)
    assert bus.sent.count(p.WRITE_DATA) == 2 and bus.servos[2]["serial"] == 0x51A00001


def test_a_lost_clear_faults_is_read_back_and_sent_again():
    bus = ErasingBus(lose=1)
    Servo(bus, 1).clear_faults()
    assert bus.values["faults"] == 0 and bus.sent == [p.CLEAR_FAULTS, p.READ_FAULTS, p.CLEAR_FAULTS]


class LateAnswerBus(p.Bus):
    """loop:// with the answers given: each request is followed on the line
    by the frames queued for it (a late answer to an earlier request first)."""

    def __init__(self, answers):
        super().__init__("loop://", 115200, timeout=0.05)
        self.answers = answers

    def send(self, code, content):
        super().send(code, content)
        self.serial.write(b"".join(p.response_frame(c, a) for c, a in self.answers.pop(0)))


def test_a_late_answer_about_another_item_is_not_this_reads():
    """current_limit's answer comes late, after the read of power_limit
    (the same size) was sent: it is not taken as power_limit's."""
    cur, power = registers.find("current_limit"), registers.find("power_limit")
    late = (p.READ_DATA, bytes([1, cur.id]) + cur.pack(3000))
    with LateAnswerBus([[late, (p.READ_DATA, bytes([1, power.id]) + power.pack(9000))]]) as bus:
        assert Servo(bus, 1).read("power_limit") == 9000


def test_a_late_answer_is_drained_before_a_read_is_sent_again():
    bus = ErasingBus(drop=1)
    Servo(bus, 1).read("current_limit")
    assert bus.drained == 1
