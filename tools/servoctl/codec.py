"""Frames of the servo protocol (docs/protocol.md, from protocol/servo_schema):
the packets' codes, requests encoded and answers decoded; protocol.py's Bus
carries them."""
import struct

import servo_schema as _schema

from .errors import BadAnswer

_SCHEMA = _schema.load()
REQUEST_HEADER = bytes(_SCHEMA.frame["request_header"])
RESPONSE_HEADER = bytes(_SCHEMA.frame["response_header"])
BROADCAST = _SCHEMA.frame["broadcast_id"]
MAX_ID = _SCHEMA.frame["max_id"]  # servo IDs are 0..254; 0xFF is broadcast
# The longest answer frame: header, code, length, content, checksum.
ANSWER_FRAME_MAX = len(RESPONSE_HEADER) + 3 + _SCHEMA.frame["answer_content_max"]
# Every packet's code by servoctl's name for it, as module constants:
# protocol.PING, protocol.WRITE_DATA, protocol.UPDATE_STATUS, ...
CODES = {pkt.py: pkt.code for pkt in _SCHEMA.packets}
globals().update(CODES)


# Requests that only read: one that gets no answer is sent once more
# (Bus.request). A request that lands in a servo's page erase is carried out
# but not answered (docs/decisions-hardware.md, "Flash and the real-time
# budget"); a read asked again changes nothing. Writes are confirmed by a
# read instead (Servo._write_kept).
REPEATABLE = frozenset(CODES[name] for name in (
    "PING", "READ_DATA", "READ_BATCH", "READ_ANGLE", "READ_MULTI_TURN", "MONITOR",
    "READ_MOTION", "READ_STORE", "READ_FAULTS"))


# What servo_sim and the virtual boards tell a second TCP client while
# another holds the bus (one program on a port at a time, as on a serial one).
BUS_IN_USE = b"the bus is in use by another client"


def checksum(data: bytes) -> int:
    return sum(data) % 256


def decode_answer(code: int, content: bytes) -> tuple:
    """An answer's fields, as protocol/servo_schema lays them out, once its
    length is the packet's: any other length is an error that says so,
    never a traceback."""
    fmt = _SCHEMA.answer_format(code)
    if len(content) != struct.calcsize(fmt):
        who = content[0] if content else "?"
        raise BadAnswer(f"servo {who}: a {_SCHEMA.packet(code).name} answer of {len(content)} bytes, "
                        f"not {struct.calcsize(fmt)} (garbled, another firmware, or two servos on one ID)")
    values = struct.unpack(fmt, content)
    for f, value in zip(_SCHEMA.packet(code).answer, values):
        if f.limits is not None and not f.limits[0] <= value <= f.limits[1]:
            # A frame made of two answers' bytes with a good checksum by chance (a cut
            # Monitor answer and the next servo's: angle -402 386 922), as C's decoder says.
            raise BadAnswer(f"servo {values[0]}: a {_SCHEMA.packet(code).name} answer's {f.name} {value} is "
                            f"beyond {f.limits[0]}..{f.limits[1]} (garbled, or two servos on one ID)")
    return values


def answer_frame_size(code: int) -> int:
    """The bytes of a packet's answer frame on the wire (its fields fixed)."""
    return len(RESPONSE_HEADER) + 3 + struct.calcsize(_SCHEMA.answer_format(code))


def field_range(code: int, name: str) -> tuple:
    """(least, most) of a request's field: the range the servo clamps or
    refuses beyond (protocol/servo_schema), else its type's."""
    return _SCHEMA.field(code, name).range


def request_format(code: int) -> str:
    """The struct format of a request's content (protocol/servo_schema)."""
    return _SCHEMA.request_format(code)


def encode_request(code: int, *values) -> bytes:
    """A request's content from its fields' values, as protocol/servo_schema
    lays them out."""
    return struct.pack(_SCHEMA.request_format(code), *values)


def request_frame(code: int, content: bytes) -> bytes:
    """A request frame; content of 255 bytes or more uses the extended length."""
    if len(content) >= 255:
        head = REQUEST_HEADER + bytes([code, 0xFF]) + struct.pack("<H", len(content))
    else:
        head = REQUEST_HEADER + bytes([code, len(content)])
    body = head + content
    return body + bytes([checksum(body)])


def _frame_size(head: bytes) -> int:
    """A response frame's bytes from its first four: header, code, the
    content's length, the content, the checksum."""
    return 4 + head[3] + 1


def response_frame(code: int, content: bytes) -> bytes:
    body = RESPONSE_HEADER + bytes([code, len(content)]) + content
    return body + bytes([checksum(body)])
