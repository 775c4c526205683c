#!/usr/bin/env python3
"""Writes the fuzz seed corpus: one file per seed, a control byte followed by
valid request frames (every packet), other servos' responses and sync frames.
Run it after changing the protocol; the output is committed."""
import pathlib
import struct

OUT = pathlib.Path(__file__).with_name("corpus")


def frame(header: bytes, code: int, content: bytes) -> bytes:
    if header == b"\x12\x4c" and len(content) >= 255:
        body = header + bytes([code, 0xFF]) + struct.pack("<H", len(content)) + content
    else:
        body = header + bytes([code, len(content)]) + content
    return body + bytes([sum(body) % 256])


def req(code: int, content: bytes) -> bytes:
    return frame(b"\x12\x4c", code, content)


def resp(code: int, content: bytes) -> bytes:
    return frame(b"\x05\x1c", code, content)


FACTORY = bytes([1, 0, 0, 0, 5, 0]) + struct.pack(
    "<HHHHHH", 10000, 4000, 8400, 651, 10000, 4000) + bytes([0, 0, 0, 0, 1, 1]) + struct.pack(
    "<Hhhh", 3000, 1350, -1350, 0)
assert len(FACTORY) == 32

SEEDS = {
    "ping": req(1, b"\x00"),
    "reset": req(2, b"\x00"),
    "read_every_item": b"".join(req(3, bytes([0, i])) for i in list(range(1, 9)) + list(range(32, 54))),
    "write_items": req(4, b"\x00\x21\x01") + req(4, b"\x00\x32\xe8\x03") + req(4, b"\x00\x35\x10\x00"),
    "write_id_and_baud": req(4, b"\x00\x22\x07") + req(1, b"\x07") + req(4, b"\x07\x24\x08"),
    "batch": req(5, b"\x00") + req(6, b"\x00" + FACTORY),
    "wheel": req(7, struct.pack("<BBHH", 0, 0x82, 90, 3)),
    "angle": req(8, struct.pack("<BhHH", 0, 900, 500, 0)),
    "damping": req(9, struct.pack("<BH", 0, 500)),
    "read_angles": req(10, b"\x00") + req(16, b"\x00"),
    "angle_interval": req(11, struct.pack("<BhHHHH", 0, 1000, 1000, 100, 200, 0)),
    "angle_velocity": req(12, struct.pack("<BhHHHH", 0, 200, 3000, 100, 200, 0)),
    "multi_turn": req(13, struct.pack("<BiIH", 0, -3686400, 4096000, 0)),
    "multi_turn_interval": req(14, struct.pack("<BiIHHH", 0, 7200, 5000, 20, 30, 0)),
    "multi_turn_velocity": req(15, struct.pack("<BiHHHH", 0, 7200, 7500, 50, 60, 0)),
    "reset_turns_origin": req(24, b"\x00\x10\x00\x00") + req(17, b"\x00") + req(23, b"\x00\x00"),
    "async": req(18, b"") + req(8, struct.pack("<BhHH", 0, 900, 500, 0)) + req(19, b"\x00"),
    "monitor": req(22, b"\x00"),
    "read_motion": req(11, struct.pack("<BhHHHH", 0, 900, 300, 100, 100, 0)) + req(0x40, b"\x00"),
    "control_response": req(4, b"\x00\x21\x01") + req(11, struct.pack("<BhHHHH", 0, 1000, 1000, 100, 200, 0)),
    "sync_monitor": req(25, bytes([22, 1, 4, 5, 6, 0, 9])) + resp(22, bytes(16)) + resp(22, bytes(16)),
    "sync_move": req(25, bytes([8, 7, 2]) + struct.pack("<BhHH", 4, 0, 0, 0) + struct.pack("<BhHH", 0, 900, 500, 0)),
    "sync_long": req(25, bytes([14, 15, 200]) + b"".join(
        struct.pack("<BiIHHH", (k + 1) % 255, k * 10, 1000, 20, 20, 0) for k in range(200))),
    "others_responses": resp(3, req(1, b"\x00")) + req(1, b"\x00"),
    "bad_checksum": req(1, b"\x00")[:-1] + b"\x00" + req(1, b"\x00"),
}


def main() -> None:
    OUT.mkdir(exist_ok=True)
    for old in OUT.glob("*.bin"):
        old.unlink()
    for name, stream in SEEDS.items():
        # Control byte 0x00: poll after every byte, fast UART, no gaps.
        (OUT / f"{name}.bin").write_bytes(b"\x00" + stream)
    print(f"wrote {len(SEEDS)} seeds to {OUT}")


if __name__ == "__main__":
    main()
