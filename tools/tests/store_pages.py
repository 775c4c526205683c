"""What the store tests on servo_sim (tests/integration) and on the virtual
boards (tests/vboard) share: a fault record as the firmware writes it, the
707-byte SyncCommand sent into a page erase, moving a bus to another baud
rate, and a fault page filled while the output is driven."""
import struct
import zlib

import pytest

from servoctl import protocol as p
from servoctl.errors import Refused
from servoctl.servo import Servo

BAUD_INDEX = {115200: 5, 1000000: 8}  # item 36


def fault_record(number: int, what: int) -> bytes:
    """A fault record as storage/fault_log.c writes it."""
    entry = struct.pack("<IIiHHHhhB", number, number, 0, 7400, 0, 0, 250, 250, what)
    head = struct.pack("<HBB", 0xFA17, 1, 0xFF) + entry + b"\xff"
    return head + struct.pack("<I", zlib.crc32(head))


def sync_move_frame(angle_decideg: int) -> bytes:
    """A SyncCommand of 64 interval moves (packet 11, 11-byte records), IDs
    1..64: 707 bytes, longer than the 256-byte ring servos once had."""
    records = b"".join(struct.pack("<BhHHHH", i, angle_decideg, 300, 50, 50, 0) for i in range(1, 65))
    return p.request_frame(p.SYNC, bytes([p.ANGLE_BY_INTERVAL, 11, 64]) + records)


def bus_to_baud(sim, ids, baud: int, timeout: float) -> None:
    """Every servo in ids, and the simulator's host, to baud (from 115200)."""
    with sim.bus(timeout=timeout) as bus:
        for i in ids:
            Servo(bus, i).write("baud", BAUD_INDEX[baud])  # answered at 115200
    sim.control(f"hostbaud {baud}")


def without_soft_start(bus, ids, hold: bool = False) -> list:
    """The servos in ids, soft start off, each holding where it is if hold
    (a held servo never erases)."""
    servos = [Servo(bus, i) for i in ids]
    for s in servos:
        s.write("soft_start_on", 0)
        if hold:
            s.hold()
    return servos


def a_clear_is_refused_on_a_full_page(servo: Servo, sim) -> None:
    """The fault history's 16 newest shown and one slot left: a watchdog
    fault while the servo holds (driven all along) takes it, and a
    ClearFaults is refused while the output is driven."""
    assert servo.read_fault(0).count == 16
    servo.write("soft_start_on", 0)
    servo.write("watchdog_action", 0)  # hold: driven all along
    servo.write("watchdog_ms", 50)
    servo.move(300, interval_ms=100)
    sim.sleep(0.3)  # the watchdog holds; its fault fills the page
    assert servo.read_fault(0).kind == "watchdog"
    with pytest.raises(Refused):
        servo.clear_faults()


def released_a_clear_is_taken(servo: Servo, sim, powercycle: str) -> None:
    """After a_clear_is_refused_on_a_full_page: nothing was cleared; the
    servo released and the bus quiet, the spare page is erased and a
    ClearFaults is taken, and kept across a power cycle (the simulator's
    control line powercycle)."""
    assert servo.read_fault(0).count == 16  # nothing cleared
    servo.stop("release")
    sim.sleep(0.5)  # released and quiet: the spare page is erased
    servo.clear_faults()  # one unanswered is read back (ReadFaults)
    sim.sleep(0.1)
    sim.control(powercycle)
    sim.sleep(0.5)  # a board's bootloader window, then the application
    assert servo.faults() == []
