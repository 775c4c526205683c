"""servobus, the host C library (tools/servobus, docs/c-library.md), against
servoctl's codec: for every packet of protocol/servo_schema and every field
at the edges of its range, the C encoder's frame is servoctl's byte for
byte, and each decodes the other's requests and answers. A value beyond a
field's range (servoctl.codec.field_range) the C library refuses, naming
the field, where servoctl's codec would pack it for the servo to clamp.
The C side is sb_crosscheck (the host build), fed every case in one run."""
import struct
import subprocess
import zlib

import pytest

import servo_schema
from servoctl import codec, registers
from servoctl.checks import MIN_RAMP_MS, check_profile
from servoctl.errors import ValueOutOfRange

from .launchers import REPO

BINARY = REPO / "build" / "host" / "tools" / "servobus" / "sb_crosscheck"
S = servo_schema.load()
SB_E_RANGE, SB_E_USAGE, SB_E_UNKNOWN_ITEM, SB_E_BAD_ANSWER, SB_E_BROADCAST = 1, 2, 4, 8, 11
USER_AREA = bytes(range(7, 7 + registers.USER_AREA_SIZE))


def c_side(lines: list) -> list:
    if not BINARY.exists():
        pytest.fail(f"{BINARY} is not built: cmake --preset host && cmake --build --preset host")
    out = subprocess.run([str(BINARY)], input="\n".join(lines) + "\n", capture_output=True, text=True,
                         timeout=60, check=True).stdout.splitlines()
    assert len(out) == len(lines)
    return out


def word(value) -> str:
    return f"x:{value.hex()}" if isinstance(value, bytes) else str(value)


def type_range(f) -> tuple:
    size, signed = servo_schema.FIELD_TYPES[f.type], f.type.startswith("i")
    return (-(1 << (8 * size - 1)), (1 << (8 * size - 1)) - 1) if signed else (0, (1 << (8 * size)) - 1)


def edge_cases(fields) -> list:
    """(values, the field out of range or None): every field at its least and
    most, and just beyond where the schema's range is narrower than its type's."""
    # A move's time at its most, so that the other fields' edges keep its ramps.
    base = [USER_AREA if f.type == "user_area" else f.range[f.name == "interval"] for f in fields]
    cases = [(base, None)]
    for k, f in enumerate(fields):
        if f.type == "user_area":
            continue
        low, high = f.range
        tlow, thigh = type_range(f)
        for value, out in ((low, None), (high, None), (low - 1, f.name), (high + 1, f.name)):
            if out and not tlow <= value <= thigh:
                continue
            values = list(base)
            values[k] = value
            cases.append((values, out))
    return cases


def record(cmd: int, k: int) -> bytes:
    """A SyncCommand's record k that C checks as a request: each servo
    once, none the broadcast ID, every value within its field's range."""
    values = (k * 7) % 255, (k * 37) % 1800 - 900, k - 15, 20 * k
    return struct.pack(S.request_format(cmd), *values[:len(S.packet(cmd).request)])


def refused(p, part: str, values: list):
    """(status, field) where the C library refuses a request within every
    field's range, as the servo would not carry it out as sent; else None."""
    if part != "request":
        return None
    named = dict(zip((f.name for f in p.request), values))
    if p.has("addressed") and not p.has("broadcast") and values[0] == S.frame["broadcast_id"]:
        return SB_E_BROADCAST, p.request[0].name
    if "data_id" in named and named["data_id"] not in {item.id for item in registers.ITEMS}:
        return SB_E_UNKNOWN_ITEM, "data_id"  # an item the schema does not have: ReadData refused as WriteData
    if "interval" in named:  # a move's time shorter than its ramps (8 and 13 ramp 20 ms): servoctl refuses it too
        try:
            check_profile(named.get("acc_interval", MIN_RAMP_MS), named.get("dec_interval", MIN_RAMP_MS),
                          named["interval"])
        except ValueOutOfRange:
            return SB_E_RANGE, "interval"
    # A wheel run for a time (action 3) shorter than its two 20 ms ramps (motion/planning.c).
    if p.code == codec.CODES["WHEEL"] and named["method"] & 0x7F == 3 and named["speed"] and \
            named["value"] < 2 * MIN_RAMP_MS:
        return SB_E_RANGE, "value"
    # A wheel action past 3, which the servo takes as a stop (servoctl names the actions 0-3 only).
    if p.code == codec.CODES["WHEEL"] and named["method"] & 0x7F > 3:
        return SB_E_RANGE, "method"
    # DriveDuty's 0 (refused) and -32768 (clamped): servoctl's drive_duty refuses both.
    if p.code == codec.CODES["DRIVE_DUTY"] and named["duty"] in (0, -32768):
        return SB_E_RANGE, "duty"
    return None


def fixed(p, part: str) -> bool:
    return getattr(S, f"{part}_format")(p.code) is not None


def test_every_fixed_request_and_answer_at_every_field_edge():
    lines, expect = [], []
    for p in S.packets:
        for part, kind in (("request", "req"), ("answer", "ans")):
            fields = getattr(p, part)
            if not fixed(p, part) or (part == "answer" and not fields):
                continue
            fmt = getattr(S, f"{part}_format")(p.code)
            for values, out in edge_cases(fields):
                lines.append(f"{kind} {p.code} " + " ".join(map(word, values)))
                if out or refused(p, part, values):
                    expect.append((p, part, values, out, refused(p, part, values)))
                    continue
                content = struct.pack(fmt, *values)
                frame = (codec.request_frame if part == "request" else codec.response_frame)(p.code, content)
                expect.append((p, part, values, None, frame))
                lines.append(f"d{kind} {frame.hex()}")  # C decodes servoctl's frame
                expect.append((p, part, values, None, "decoded"))
    answers = c_side(lines)
    checked = 0
    for line, got, (p, part, values, out, frame) in zip(lines, answers, expect):
        if isinstance(frame, tuple) and not out:
            assert got.split()[:2] == ["err", str(frame[0])] and got.split()[3] == frame[1], (line, got)
        elif out:
            assert got.split()[:2] == ["err", str(SB_E_RANGE)] and got.split()[3] == out, (line, got)
            assert not S.field(p.code, out, part).range[0] <= values[[f.name for f in getattr(p, part)].index(out)] \
                <= S.field(p.code, out, part).range[1]
        elif frame == "decoded":
            assert got == " ".join(["ok", str(p.code), *map(word, values)]), (p.name, part, line, got)
        else:
            assert got == f"ok {frame.hex()}", (p.name, part, line, got)
            # servoctl decodes the C library's frame.
            c_frame = bytes.fromhex(got[3:])
            fmt = getattr(S, f"{part}_format")(p.code)
            assert list(struct.unpack(fmt, c_frame[4:-1])) == values
            if part == "answer":
                assert list(codec.decode_answer(p.code, c_frame[4:-1])) == values
            checked += 1
    assert checked > 200


def test_data_items_at_their_sizes_and_ranges():
    """WriteData's value and ReadData's answer take each item's size and
    range; an item WriteData cannot write is refused."""
    lines, expect = [], []
    for item in registers.ITEMS:
        edges = (item.low, item.high, item.low - 1, item.high + 1) if item.writable else ()
        for value in edges:
            inside = item.low <= value <= item.high
            lines.append(f"req {codec.CODES['WRITE_DATA']} 3 {item.id} {value}")
            expect.append(codec.request_frame(4, bytes([3, item.id]) + item.pack(value)) if inside else SB_E_RANGE)
        if not item.writable:
            lines.append(f"req 4 3 {item.id} 0")
            expect.append(SB_E_UNKNOWN_ITEM)
        bits = 8 * item.size
        value = -(1 << (bits - 1)) if item.signed else (1 << bits) - 1
        answer = codec.response_frame(3, bytes([3, item.id]) + (item.pack(value) if item.public else b""))
        lines.append(f"dans {answer.hex()}")
        expect.append(f"ok 3 3 {item.id} {value if item.public else '-'}")
        if item.public:
            lines.append(f"ans 3 3 {item.id} {value}")
            expect.append(answer)
    for line, got, want in zip(lines, c_side(lines), expect):
        if isinstance(want, bytes):
            assert got == f"ok {want.hex()}", (line, got)
        elif isinstance(want, str):
            assert got == want, (line, got)
        else:
            assert got.split()[:2] == ["err", str(want)], (line, got)


def test_blocks_and_sync_commands():
    """UpdateWrite's block (1 to 24 bytes: none or more the bootloader
    drops unanswered, and the C library refuses), SyncCommand's records
    (the extended length from 255 content bytes), and each decoded back."""
    lines, frames = [], []
    refused_blocks = [f"req 82 5 4096 {word(bytes(n))} 0" for n in (0, 25)]
    assert [a.split()[:2] for a in c_side(refused_blocks)] == [["err", str(SB_E_USAGE)]] * 2
    for n in (1, 8, 24):
        chunk = bytes(range(n))
        content = bytes([5]) + struct.pack("<I", 4096) + chunk + struct.pack("<I", zlib.crc32(chunk))
        lines.append(f"req 82 5 4096 {word(chunk)} {zlib.crc32(chunk)}")
        frames.append(codec.request_frame(codec.CODES["UPDATE_WRITE"], content))
    for cmd, rlen, count in ((22, 1, 16), (0x45, 9, 6), (0x45, 9, 30)):
        records = b"".join(record(cmd, k) for k in range(count))
        lines.append(f"req 25 {cmd} {rlen} {count} {word(records)}")
        frames.append(codec.request_frame(codec.CODES["SYNC"], bytes([cmd, rlen, count]) + records))
    got = c_side(lines + [f"dreq {f.hex()}" for f in frames])
    for line, answer, frame in zip(lines, got, frames):
        assert answer == f"ok {frame.hex()}", line
    for line, answer in zip(lines, got[len(lines):]):
        assert answer == "ok " + line[4:], line
    assert frames[-1][3] == 0xFF  # 273 content bytes: the extended length


def test_answers_of_another_length_are_refused_by_both():
    """Every fixed answer one byte longer or shorter than the schema's:
    C says SB_E_BAD_ANSWER where servoctl raises BadAnswer (a decoder that
    took trailing bytes passed every other case here)."""
    lines, cases = [], []
    for p in S.packets:
        if not fixed(p, "answer") or not p.answer:
            continue
        content = struct.pack(S.answer_format(p.code), *edge_cases(p.answer)[0][0])
        for bad in (content + b"\x00", content[:-1]):
            lines.append(f"dans {codec.response_frame(p.code, bad).hex()}")
            cases.append((p, bad))
    for line, got, (p, bad) in zip(lines, c_side(lines), cases):
        assert got.split()[:2] == ["err", str(SB_E_BAD_ANSWER)], (p.name, line, got)
        with pytest.raises(codec.BadAnswer):
            codec.decode_answer(p.code, bad)
    assert len(cases) > 40


def test_the_extended_length_begins_at_255_content_bytes():
    """A SyncCommand of 254, 255 and 256 content bytes: the short length
    to 254, the extended from 255 (0xFF is its mark), as servoctl's."""
    lines, frames = [], []
    for count in (251, 252, 253):
        records = bytes((k * 7) % 255 for k in range(count))  # each servo once, none the broadcast ID
        lines.append(f"req 25 22 1 {count} {word(records)}")
        frames.append(codec.request_frame(codec.CODES["SYNC"], bytes([22, 1, count]) + records))
    got = c_side(lines + [f"dreq {f.hex()}" for f in frames])
    for line, answer, frame in zip(lines, got, frames):
        assert answer == f"ok {frame.hex()}", line
    for line, answer in zip(lines, got[len(lines):]):
        assert answer == "ok " + line[4:], line
    assert [f[3] for f in frames] == [254, 0xFF, 0xFF] and len(frames[1]) == 255 + 7
