"""Power cuts through servoctl's update of a new image (servoctl/update.py:
UpdateEnter, the slot's pages erased, the image written in blocks with the
header's checked bytes last, verified, booted) on the G0's virtual board, the
shipped images: the update's flash operations counted first, then the
update run again from the same flash image with the power cut as one of
them begins (cutflash; on the G0 a cut program step leaves its double word
torn, a cut erase its page half erased and torn, vboard/g0.py).

After each cut the board answers within a second of simulated time, in its
bootloader (every cut comes at or after the first erase, which makes the
old image invalid), and stays there: a half image is never started. Then
servoctl's update from the start brings the new image, which runs. And an
update the cut interrupts goes on by itself (servoctl's retries meet the
restarted bootloader): on the G0 the torn block is refused as neither
erased nor holding its bytes, and servoctl erases its page and writes it
again, the pages a write straddles both. Not every operation is cut: an
update of the G0 (14 erases, about 3 550 program steps) is about 6 s of CPU here,
so the erases of the header's page and of the last, and the program steps
where the order matters: a page's last, the header's first and its last
(the step that makes the image valid); the update going on after
a cut at a page's first step (its write straddles two pages) and at the
header's second. The F1/F0 are left to test_virtual_boards' update cuts
(a cut a third of the way, and one in a program step). Runs in this
process (power_cuts.py); time is simulated."""
import pytest

from servoctl import image as img
from servoctl import protocol as p
from servoctl import update as upd
from servoctl.servo import Servo
from vboard.board import board_h, images

from .power_cuts import Cuts

NEW = 0x0042  # the new image's version; the shipped one is 0x0010


class Cut(Exception):
    """The power went: the host stops where it was."""


@pytest.fixture
def g0(tmp_path):
    c = Cuts("stm32g031k8", str(tmp_path / "state"))
    try:
        yield c
    finally:
        c.close()


def new_image(board: str):
    _, _, app = images(board)
    return img.parse(img.build(app.read_bytes(), NEW, img.boards()[board].id))


def counted_update(cuts, new) -> tuple:
    """The update, its flash operations counted: (kinds, operations before
    the UpdateVerify) from the saved image, the application running."""
    verify_at, request, ops0 = [], cuts.host.request, cuts.flash.ops

    def marking(code, content, timeout=None, again=None):
        if code == upd.UPDATE_VERIFY and not verify_at:
            verify_at.append(cuts.flash.ops - ops0)
        return request(code, content, timeout)

    cuts.host.request = marking
    try:
        kinds = cuts.count(lambda: upd.update(cuts.host, 1, new))
    finally:
        del cuts.host.request
    return kinds, verify_at[0]


def programmed(data: bytes, unit: int) -> list:
    """The slot offsets the update's program steps write, in order: the
    blocks after the header's, then the header's (servoctl's 24-byte
    writes); a unit that is to hold 0xFF is erased already, not programmed."""
    data += b"\xff" * (-len(data) % unit)
    head = -(-img.CHECKED // 24) * 24
    order = list(range(head, len(data), unit)) + list(range(0, head, unit))
    return [o for o in order if data[o:o + unit] != b"\xff" * unit]


def cut_points(kinds: list, pages: int, steps: list, page_size: int) -> dict:
    """Where to cut (1 the first operation), and why: steps are the
    offsets programmed (programmed())."""
    header = next(i for i, o in enumerate(steps) if o < page_size and i and steps[i - 1] > o)
    page2 = steps.index(2 * page_size)
    at = {1: "page 0's erase (the header's)", pages: "the last page's erase",
          pages + page2: "page 1's last program step",
          pages + header + 1: "the header's first program step",
          pages + len(steps): "the header's last program step (the image made valid)"}
    assert all(kinds[:pages]) and not any(kinds[pages:pages + len(steps)])
    return at


def stopped_at_the_cut(cuts, new):
    """servoctl's update, stopped where the power went (Cut)."""
    resets, request = cuts.board.resets["power"], cuts.host.request

    def cut_short(code, content, timeout=None, again=None):
        if cuts.board.resets["power"] > resets:
            raise Cut()
        return request(code, content, timeout)

    cuts.host.request = cut_short
    try:
        upd.update(cuts.host, 1, new)
    except Cut:
        pass
    finally:
        del cuts.host.request


def test_an_update_cut_at_its_erases_and_program_steps_leaves_the_bootloader_then_updates(g0):
    cuts, new = g0, new_image(g0.board.name)
    assert cuts.in_application()
    image = cuts.save()
    kinds, verify_at = counted_update(cuts, new)
    st = upd.status(cuts.host, 1)
    assert (st.mode, st.version) == (upd.MODE_APP, NEW)
    unit, page = cuts.board.part_facts["program_unit"], board_h(cuts.board.name)["BOARD_FLASH_PAGE"]
    pages = -(-len(new.data) // page)
    steps = programmed(new.data, unit)
    assert verify_at == pages + len(steps), (verify_at, pages, len(steps))
    points = cut_points(kinds, pages, steps, page)
    for k, what in points.items():
        cuts.put_back(image)
        assert cuts.in_application()
        assert cuts.cut_at(k, lambda: stopped_at_the_cut(cuts, new)), f"no cut at {what}"
        assert cuts.boots(), f"no answer after a cut at {what}"
        st = upd.status(cuts.host, 1)
        assert st.mode == upd.MODE_BOOTLOADER and st.verdict != 0, (what, st)
        cuts.host.sleep(0.5)
        assert not cuts.board.in_application(), f"a half image started after a cut at {what}"
        before, after = upd.update(cuts.host, 1, new)
        assert (before, after) == (None, NEW), what
        assert cuts.in_application() and Servo(cuts.host, 1).read("firmware") == NEW, what
    print(f"{cuts.board.name}: an update of {len(kinds)} flash operations ({verify_at} before its "
          f"verify, {sum(kinds)} erases), cut at {len(points)}")


@pytest.mark.parametrize("where", ["page 2", "header", "zeros"])
def test_an_update_goes_on_after_a_cut_mending_the_torn_block(g0, where):
    """servoctl's update, not stopped: its retries reach the restarted
    bootloader, which refuses the torn block (reason 5); the page is erased
    and written again, and the update ends with the new image running.
    Cut at page 2's first step (its write straddles pages 1 and 2), the
    header's second, and a block that is to hold zeros (which is what a
    torn double word reads as)."""
    cuts, new = g0, new_image(g0.board.name)
    assert cuts.in_application()
    unit, pages = cuts.board.part_facts["program_unit"], -(-len(new.data) // 2048)
    steps = programmed(new.data, unit)
    zeros = next(o for o in steps if o > 2 * 2048 and new.data[o:o + 8] == bytes(8))
    at = {"page 2": 2 * 2048, "header": 8, "zeros": zeros}[where]
    k = pages + 1 + steps.index(at)
    erases, request = [], cuts.host.request

    def seen(code, content, timeout=None, again=None):
        if code == p.UPDATE_ERASE and cuts.board.resets["power"] > 1:
            erases.append(content[1])
        return request(code, content, timeout)

    cuts.host.request = seen
    done = []
    assert cuts.cut_at(k, lambda: done.append(upd.update(cuts.host, 1, new))), "no cut"
    del cuts.host.request
    assert done == [(0x0010, NEW)]
    assert erases == {"page 2": [1, 2], "header": [0], "zeros": [zeros // 2048]}[where], erases
    assert cuts.in_application() and Servo(cuts.host, 1).read("firmware") == NEW
