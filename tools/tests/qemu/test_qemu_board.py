"""The real ARM image (real USART driver, real core; plant model compiled
in) on QEMU's stm32vldiscovery, driven by servoctl over socket://. Every
wait is on QEMU's progress (board.bus(): the CPU time QEMU has had), so a
loaded machine that starves QEMU makes the tests slower, not failed."""
import struct

import pytest

from servoctl import protocol as p
from servoctl.servo import Servo

from ..launchers import QemuBoard


@pytest.fixture(scope="module")
def board():
    with QemuBoard() as b:
        yield b


@pytest.fixture
def servo(board):
    with board.bus(timeout=0.3) as bus:
        yield Servo(bus, 0)


def test_ping(servo):
    assert servo.ping()
    assert servo.read("serial") == 0x0E3A0001  # the emulated board's
    assert servo.read("model") == 0x0F00


def test_it_runs_from_its_slot_through_the_bootloader(servo):
    """The application is linked after the bootloader and its image header:
    QEMU starts the bootloader, which checks the image and jumps to it."""
    from servoctl import update as upd
    st = upd.status(servo.bus, 0)
    assert (st.mode, st.board) == (upd.MODE_APP, 0x0100)


def test_update_enter_and_boot_round_trip(servo):
    """UpdateEnter: the application leaves the word in RAM and restarts;
    the bootloader stays, answers Ping and UpdateStatus (the image checks),
    and UpdateBoot starts the application again."""
    from servoctl import update as upd
    assert servo.bus.request(upd.UPDATE_ENTER, bytes([0]))[1] == 1
    st = upd._wait_for_mode(servo.bus, 0, upd.MODE_BOOTLOADER)
    assert (st.verdict, st.bootloader_version, st.page_size) == (0, 3, 1024)
    assert servo.ping()
    assert servo.bus.request(upd.UPDATE_BOOT, bytes([0]))[1] == 1
    upd._wait_for_mode(servo.bus, 0, upd.MODE_APP)
    assert servo.read("serial") == 0x0E3A0001


def test_the_bootloader_drops_a_partial_frame(servo):
    """The real ARM bootloader: the start of a frame whose length says
    65535, then a frame cut short, each dropped after the idle gap (this
    board's 50 ms tolerance of QEMU's jitter), not waited on for good."""
    from servoctl import update as upd
    assert servo.bus.request(upd.UPDATE_ENTER, bytes([0]))[1] == 1
    upd._wait_for_mode(servo.bus, 0, upd.MODE_BOOTLOADER)

    def answers_again():
        """QEMU hands bytes over when its main loop runs, so on a starved
        host the next request can reach the guest before it has seen the
        gap, and is dropped with the partial frame: a deaf bootloader
        answers none of three, a working one the next after that gap."""
        for _ in range(3):
            servo.bus.sleep(0.2)
            if servo.ping():
                return True
        return False

    servo.bus.serial.write(bytes([0x12, 0x4C, 0x55, 0xFF, 0xFF, 0xFF]))
    assert answers_again()
    whole = p.request_frame(upd.UPDATE_WRITE, bytes([0]) + bytes(4) + b"\xff" * 8 + bytes(4))
    servo.bus.serial.write(whole[:10])
    assert answers_again()
    assert upd.status(servo.bus, 0).mode == upd.MODE_BOOTLOADER
    assert servo.bus.request(upd.UPDATE_BOOT, bytes([0]))[1] == 1
    upd._wait_for_mode(servo.bus, 0, upd.MODE_APP)


def test_read_and_write_data(servo):
    assert servo.read("voltage") == pytest.approx(7400, abs=10)
    assert servo.read("temperature") == 2048
    servo.write("stall_power", 4321)
    assert servo.read("stall_power") == 4321
    servo.bus.send(p.WRITE_DATA, bytes([0, 53]) + struct.pack("<h", 1801))  # out of range
    assert servo.bus.read_response(p.WRITE_DATA, 0)[2] == 0


def test_batch_read_and_write(servo):
    values = servo.read_all()
    assert values["check_flag"] == 1 and values["baud"] == 5
    values["current_limit"] = 3000
    values["angle_max"] = 900
    servo.write_all(values)
    assert servo.read_all() == values
    servo.reset_user_data()
    assert servo.read("current_limit") == 4000


def wait_until_done(servo, limit_s=5.0):
    """Polls the executing bit. QEMU drops control ticks when the host is
    busy, which stretches a move in wall time, so no fixed sleep."""
    bus = servo.bus
    t0 = bus.clock()
    bus.sleep(0.05)
    while servo.status() & 1:
        assert bus.clock() - t0 < limit_s, "the move did not finish"
        bus.sleep(0.01)
    bus.sleep(0.3)  # settle


def test_move_and_read_back(servo):
    servo.write("soft_start_on", 0)
    servo.move(angle_decideg=900, interval_ms=500)
    wait_until_done(servo)
    assert abs(servo.angle() - 900) <= 5
    assert abs(servo.multi_turn_angle()[0] - 900) <= 5
    servo.move(angle_decideg=-450, velocity=3000, acc_ms=100, dec_ms=100)
    wait_until_done(servo)
    assert abs(servo.monitor().angle_decideg + 450) <= 5


def test_bad_checksum_then_good_frame(servo):
    frame = bytearray(p.request_frame(p.PING, bytes([0])))
    frame[-1] ^= 0xFF
    servo.bus.serial.write(bytes(frame))
    servo.bus.sleep(0.05)
    assert servo.bus.serial.read(100) == b""  # no answer to it
    assert servo.ping()                      # the next good one is answered


def test_request_for_another_id_is_ignored(servo):
    servo.bus.serial.write(p.request_frame(p.PING, bytes([7])))
    servo.bus.serial.write(p.request_frame(p.READ_DATA, bytes([9, 1])))
    servo.bus.sleep(0.1)
    assert servo.bus.serial.read(100) == b""
    assert servo.ping()
