"""Power cuts at every flash operation of the config store's and the fault
history's work on the virtual boards (the shipped images): the sequence's
operations counted first (program steps and page erases, the flash model's
flash_ops), then the sequence run again from the same flash image with the
power cut as each one begins (cutflash; a cut erase leaves its page half
erased, on the G0 with a torn double word, vboard/g0.py). After each cut
the board boots, keeps what it had acknowledged (the value before, or the
new one for the save in flight; never another), and its next save works.
Every operation is cut on the G0; a spread of them on the F1/F0 (EVERY).
Runs in this process (power_cuts.py); time is the boards' simulated time."""
import struct

import pytest

from servoctl import protocol as p
from servoctl.protocol import NoReply
from servoctl.servo import Servo
from vboard.board import board_h

from ..store_pages import fault_record
from .power_cuts import Cuts, cut_points
from .test_virtual_boards import BOARDS

ANGLE_MAX = 51
# Every operation on the G0 (a record is 9 double words, a fault's 4); on the
# F1/F0, whose steps are half-words (36 and 16), each erase, the first and
# last two steps and every 12th: every one there costs 60 s of CPU a run.
EVERY = {"stm32g031k8": 1, "stm32f103": 12, "stm32f030k6": 12}
RECORD = 72  # a config record's bytes (config_record.h: 12 + the stored items + 4, to 8)


@pytest.fixture(params=BOARDS)
def cuts(request, tmp_path):
    c = Cuts(request.param, str(tmp_path / "state"))
    try:
        yield c
    finally:
        c.close()


def write_angle_max(cuts, value: int) -> bool:
    """A WriteData of item 51; True if the servo answered that it took it."""
    try:
        answer = cuts.host.request(p.WRITE_DATA, bytes([1, ANGLE_MAX]) + struct.pack("<h", value), timeout=0.05)
    except NoReply:
        return False
    return answer[-1] == 1


def test_a_config_save_that_starts_the_other_page_survives_a_cut_at_every_operation(cuts):
    """The store's page full: the save programs slot 0 of the spare page
    (erased beforehand), then the full page, now the spare, is erased once
    the line is quiet: a record's program steps and an erase."""
    servo = Servo(cuts.host, 1)
    slots = board_h(cuts.board.name)["BOARD_FLASH_PAGE"] // RECORD
    n = 0
    while servo.read_store().records % slots != 0:
        n += 1
        servo.write("current_limit", 3000 + n % 2)
    cuts.host.sleep(0.3)  # released and quiet: the spare page erased, if it was not
    old, new = servo.read("angle_max"), 1000
    image = cuts.save()

    def save():
        acked.append(write_angle_max(cuts, new))
        cuts.host.sleep(0.4)  # the line quiet: the old page erased

    acked = []
    kinds = cuts.count(save)
    unit = cuts.board.part_facts["program_unit"]
    assert acked == [True] and kinds == [False] * (RECORD // unit) + [True], kinds
    points = cut_points(kinds, EVERY[cuts.board.name])
    for k in points:
        cuts.put_back(image)
        assert cuts.in_application()
        acked.clear()
        assert cuts.cut_at(k, save), f"no cut at operation {k}"
        assert cuts.boots(), f"no answer after a cut at operation {k} of {len(kinds)}"
        assert cuts.in_application(), f"the application did not start after a cut at {k}"
        value = servo.read("angle_max")
        assert value == new if acked[0] else value in (old, new), (k, value)
        servo.write("angle_max", 900)
        cuts.board.power_cycle()
        assert cuts.in_application(), (k, cuts.runner.command("state 1"))
        assert servo.read("angle_max") == 900, k
    print(f"{cuts.board.name}: a page change's save, {len(kinds)} operations, cut at {len(points)}")


def test_a_fault_record_and_the_erase_before_it_survive_a_cut_at_every_operation(cuts):
    """The history's page in use holding 15 records, the other page full of
    older ones, the oldest of the 16 shown: a brown-out's record is the
    16th in the page in use, and the other page, the spare, shown no more,
    is erased once the line is quiet. After a cut the
    faults shown are those before, or the new one in front of them; the
    next fault (a watchdog reset) is kept."""
    h, board = board_h(cuts.board.name), cuts.board
    per_page = min(h["BOARD_FLASH_PAGE"] // 32, 64)
    for page, first, n in ((h["BOARD_FAULT_PAGE1"], 1, per_page), (h["BOARD_FAULT_PAGE0"], per_page + 1, 15)):
        cuts.write_flash(page, b"".join(fault_record(first + i, 2) for i in range(n)))
    image = cuts.save()
    cuts.put_back(image)
    assert cuts.in_application()
    servo = Servo(cuts.host, 1)
    before = [(f.number, f.what) for f in servo.faults()]
    assert len(before) == 16 and before[0] == (per_page + 15, 2)

    def brownout():
        board.brownout()
        cuts.in_application()
        cuts.host.sleep(0.5)

    kinds = cuts.count(brownout)
    after = [(f.number, f.what) for f in servo.faults()]
    assert after[0][1] == 13 and after[1:] == before[:15], after
    assert kinds == [False] * (32 // board.part_facts["program_unit"]) + [True], kinds
    points = cut_points(kinds, EVERY[cuts.board.name])
    for k in points:
        cuts.put_back(image)
        assert cuts.in_application()
        assert cuts.cut_at(k, brownout), f"no cut at operation {k}"
        assert cuts.boots() and cuts.in_application(), f"no start after a cut at operation {k} of {len(kinds)}"
        cuts.host.sleep(0.5)
        shown = [(f.number, f.what) for f in servo.faults()]
        assert shown[:16] == before or (shown[0][1] == 13 and shown[1:] == before[:15]), (k, shown)
        board.injector.inject("hang")
        cuts.host.run(cuts.runner.now_s + 0.5, lambda: board.resets["watchdog"] > 0)
        assert cuts.in_application()
        cuts.host.sleep(0.5)
        newest = servo.faults()
        assert newest[0].what == 11 and [(f.number, f.what) for f in newest[1:]] == shown[:15], (k, newest)
    print(f"{cuts.board.name}: a fault record and its erase, {len(kinds)} operations, cut at {len(points)}")


def test_a_page_change_that_finds_the_spare_not_erased_survives_a_cut_at_each_operation(tmp_path):
    """A host writes a page of records with the line never quiet for 0.1 s:
    the page left, the spare now, is not erased, so when the page in use is
    full the next change is refused (ReadStore's bit 3, nothing lost: it was
    not acknowledged), the spare is erased once the line is quiet, the change
    sent again lands in its slot 0, and the full page is erased in turn.
    The power cut as each of those operations begins (the spare's erase
    leaves it half erased, torn at its middle): the board starts (erasing a
    spare that is not erased), keeps every change it acknowledged, and saves
    again. On the G0, whose program steps are double words (9 a record)."""
    cuts = Cuts("stm32g031k8", str(tmp_path / "state"))
    try:
        servo = Servo(cuts.host, 1)
        slots = board_h(cuts.board.name)["BOARD_FLASH_PAGE"] // RECORD
        while servo.read_store().records % slots != 0:
            servo.write("current_limit", 3000 + servo.read_store().records % 2)
        cuts.host.sleep(0.3)  # quiet: the spare erased
        old, new = servo.read("angle_max"), 1000
        image = cuts.save()
        acked = []

        def page_change():
            for n in range(slots):  # the other page filled, the one left not erased
                servo.write("current_limit", 2000 + n % 2)
            acked.append(write_angle_max(cuts, new))  # refused: no erased slot
            cuts.host.sleep(0.3)  # quiet: the spare erased
            acked.append(write_angle_max(cuts, new))
            cuts.host.sleep(0.4)  # the full page erased

        kinds = cuts.count(page_change)
        steps = RECORD // cuts.board.part_facts["program_unit"]  # a record's program steps
        tail = [True] + [False] * steps + [True]
        assert acked == [False, True] and kinds == [False] * (slots * steps) + tail, kinds
        first = len(kinds) - len(tail) + 1
        for k in range(first, len(kinds) + 1):
            cuts.put_back(image)
            assert cuts.in_application()
            acked.clear()
            assert cuts.cut_at(k, page_change), f"no cut at operation {k}"
            assert cuts.boots() and cuts.in_application(), f"no start after a cut at operation {k}"
            assert acked[0] is False and servo.read("current_limit") == 2000 + (slots - 1) % 2, k
            value = servo.read("angle_max")
            assert value == new if acked[1:] == [True] else value in (old, new), (k, value)
            servo.write("angle_max", 900)
            cuts.board.power_cycle()
            assert cuts.in_application() and servo.read("angle_max") == 900, k
        print(f"{cuts.board.name}: a page change that finds the spare not erased, {len(kinds)} "
              f"operations, cut at the last {len(kinds) - first + 1}")
    finally:
        cuts.close()
