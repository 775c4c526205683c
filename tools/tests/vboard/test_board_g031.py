"""The STM32G031K8's virtual board: what the G0 has that the F0/F1 boards
do not. Its flash interface driven directly (vboard/g0.py, RM0444 3.3.7,
3.7): a program operation is a double word, its second word starts it, a
double word programmed is not programmed again (PROGERR), a page is
erased by its number; a double word the power cut while it programmed
reads as a double ECC error (ECCR's ECCD, the NMI). And the shipped arm-g0
images on it: the application (not the bootloader) answers, on the PLL's
64 MHz, and a torn config record costs an NMI, not the servo. Time is the
board's simulated time."""
import struct

import pytest
from unicorn import arm_const as arm

from servoctl import protocol as p
from servoctl import update as upd
from servoctl.servo import Servo
from vboard import bench
from vboard.flash import KEY1, KEY2
from vboard.g0 import NMI

from .test_virtual_boards import finish, start

BOARD = "stm32g031k8"
PG, PER, STRT, PNB_SHIFT = 1, 2, 1 << 16, 3            # FLASH_CR (RM0444 3.7.5)
PROGERR, PGAERR, PGSERR = 1 << 3, 1 << 5, 1 << 7       # FLASH_SR (RM0444 3.7.4)
ECCD, ADDR_ECC = 1 << 31, 0x3FFF                       # FLASH_ECCR (RM0444 3.7.6)


@pytest.fixture
def board(tmp_path):
    r = bench.runner_for(BOARD, [1], str(tmp_path / "state"))
    try:
        yield r.boards[0]
    finally:
        r.bus.close()
        r.control.close()
        r.clock.close()


def unlocked(flash):
    flash._keyr(KEY1, 0, 4)
    flash._keyr(KEY2, 0, 4)
    assert not flash.get("CR") & (1 << 31)


def program(flash, address, lo, hi):
    flash.put("CR", PG)
    flash._store(address, lo, 4)
    flash._store(address + 4, hi, 4)


def test_a_double_word_programs_once_and_a_page_erases_by_number(board):
    flash, base = board.flash, board.flash_base
    unit = base + 30 * 2048 + 1024        # page 30 of 32: the config store's first, past its records
    other = base + 31 * 2048 + 2040       # its last double word: page 31's
    unlocked(flash)
    flash.put("CR", PG)
    flash._store(unit, 0x11223344, 4)     # the first word alone programs nothing
    assert flash.memory.read(unit - base, 8) == b"\xff" * 8
    flash._store(unit + 4, 0x55667788, 4)
    assert flash.memory.read(unit - base, 8) == struct.pack("<II", 0x11223344, 0x55667788)
    assert not flash.get("SR") & (PROGERR | PGAERR | PGSERR)
    program(flash, unit, 0xFFFFFFFF, 0)   # a second write of a programmed double word
    assert flash.get("SR") & PROGERR
    assert flash.memory.read(unit - base, 8) == struct.pack("<II", 0x11223344, 0x55667788)
    flash.put("SR", 0)
    program(flash, unit, 0, 0)            # all zeros may be written over it
    assert flash.memory.read(unit - base, 8) == bytes(8) and not flash.get("SR") & PROGERR
    flash.put("CR", PG)
    flash._store(unit + 12, 1, 4)         # not a double word's first word
    assert flash.get("SR") & PGAERR
    flash.put("SR", 0)
    flash.put("CR", 0)
    flash._store(unit + 8, 1, 4)          # no PG: a sequence error
    assert flash.get("SR") & PGSERR
    flash.put("SR", 0)
    program(flash, other, 0x12345678, 0x9ABCDEF0)
    flash._cr(PER | 30 << PNB_SHIFT | STRT, PER | 30 << PNB_SHIFT, 4)
    assert flash.memory.read(30 * 2048, 2048) == b"\xff" * 2048
    assert flash.memory.read(other - base, 8) == struct.pack("<II", 0x12345678, 0x9ABCDEF0)  # page 31 kept
    assert flash.erases == 1 and flash.stalled_s >= 40e-3


def test_a_double_word_torn_by_a_power_cut_is_an_ecc_error_until_erased(board):
    flash, base = board.flash, board.flash_base
    unit = base + 31 * 2048 + 2032        # page 31's last double word but one
    unlocked(flash)
    flash.cut_after_programs = 1
    program(flash, unit, 0x01020304, 0x05060708)
    assert board.core.reset_cause == "power"
    board.core.reset_cause = None
    assert unit - base in flash.torn
    # A load of it (the running core's): ECCD with the double word's offset, and the NMI
    board.core.uc.mem_write(0x20000000, bytes.fromhex("0068fee7"))  # ldr r0, [r0]; b .
    board.core.uc.reg_write(arm.UC_ARM_REG_R0, unit)
    board.core.pending.clear()
    board.core.uc.emu_start(0x20000001, 0x20000004, count=4)
    assert NMI in board.core.pending
    eccr = flash.get("ECCR")
    assert eccr & ECCD and eccr & ADDR_ECC == (unit - base) >> 3
    flash._eccr(ECCD, eccr, 4)            # written 1: cleared
    flash._cr(PER | 31 << PNB_SHIFT | STRT, PER | 31 << PNB_SHIFT, 4)
    assert unit - base not in flash.torn  # erased: whole again


def test_the_application_answers_on_the_pll(tmp_path):
    sim = start(tmp_path, BOARD)
    with sim.bus(timeout=0.3) as bus:
        assert Servo(bus, 1).ping()
        assert upd.status(bus, 1).mode == upd.MODE_APP  # UpdateStatus: the application's answer
        state = sim.state(1)
        assert state["mode"] == "app" and state["core_mhz"] == 64.0  # PLLRCLK: 16 MHz x 8 / 2
        assert Servo(bus, 1).read("serial") != 0  # the unique ID at 0x1FFF7590 (RM0444 40.1)
    finish(sim, [1])


def test_a_config_record_torn_by_a_power_cut_costs_an_nmi_not_the_servo(tmp_path):
    sim = start(tmp_path, BOARD)
    with sim.bus(timeout=0.3) as bus:
        servo = Servo(bus, 1)
        old = servo.read("angle_max")
        sim.control("cutprogram 1 1")   # the record's first double word, torn
        bus.send(p.WRITE_DATA, bytes([1, 51]) + struct.pack("<h", 1000))
        sim.sleep(0.6)
        state = sim.state(1)
        assert state["resets_power"] == 2 and state["mode"] == "app"
        taken = dict(pair.split(":") for pair in state["exceptions_taken"].split(","))
        # One a load of it: the bootloader's (a byte a load, 8) and the application's (a word, 2)
        assert 1 <= int(taken.get(str(NMI), 0)) <= 16
        assert servo.read("angle_max") == old
        servo.write("angle_max", 900)
        sim.control("powercycle 1")
        sim.sleep(0.6)
        assert servo.read("angle_max") == 900
    finish(sim, [1])


def test_an_erase_cut_by_the_power_leaves_its_page_half_erased_and_torn(board):
    """cutflash: the power goes as the Nth operation begins, program or
    erase alike (flash_ops counts them). An erase cut short leaves page 31
    neither erased nor as it was: its first half erased, the double word at
    its middle torn (a torn unit in that half mended), the rest kept."""
    flash, base = board.flash, board.flash_base
    page = base + 31 * 2048
    unlocked(flash)
    program(flash, page, 0x11111111, 0x22222222)
    program(flash, page + 2040, 0x33333333, 0x44444444)
    flash.cut_after_programs = 1
    program(flash, page + 8, 5, 6)        # torn, in the half the erase reaches
    board.core.reset_cause = None
    assert page + 8 - base in flash.torn and flash.ops == 3
    flash.cut_after_ops = 2
    program(flash, page + 16, 7, 8)       # the first operation: programmed
    assert board.core.reset_cause is None
    flash._cr(PER | 31 << PNB_SHIFT | STRT, PER | 31 << PNB_SHIFT, 4)  # the second: cut
    assert board.core.reset_cause == "power" and flash.ops == 5 and flash.erases == 1
    assert flash.memory.read(31 * 2048, 1024) == b"\xff" * 1024
    assert flash.memory.read(31 * 2048 + 2040, 8) == struct.pack("<II", 0x33333333, 0x44444444)
    assert sorted(flash.torn) == [31 * 2048 + 1024]


def test_an_nmi_a_torn_read_left_pending_goes_with_a_power_cut(board):
    """A torn double word read as a run of the core ended (its NMI due at
    the next instruction), then the power cut: the NMI was taken at the
    new run's first instruction, ECCR already cleared by the reset, so the
    firmware took it for a fault and reset itself (the power-cut tests saw
    a software reset and a lost save)."""
    flash, base = board.flash, board.flash_base
    unlocked(flash)
    flash.cut_after_programs = 1
    program(flash, base + 31 * 2048, 1, 2)
    board.core.reset_cause = None
    flash._torn_read(board.core.uc, 0, base + 31 * 2048, 4, 0, None)
    assert NMI in board.core.pending
    board.power_cycle()
    assert NMI not in board.core.pending
