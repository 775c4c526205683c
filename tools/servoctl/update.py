"""Firmware update over the bus (docs/packets.md, 0x50-0x55): one servo at a
time, the others on the bus untouched. From the application it asks for the
bootloader (UpdateEnter); a servo already in its bootloader (an update cut
short, a broken application) is updated the same way, which is the
recovery. Every step survives a lost answer: erase, write (bootloader
version 2 on) and verify are sent again; after UpdateEnter and UpdateBoot,
the mode the servo answers in says whether the request was carried out."""
import struct
import zlib
from dataclasses import dataclass

from . import protocol as _p
from .image import CHECKED, Image, board_named
from .errors import NotSent
from .protocol import BadAnswer, NoReply, Refused

UPDATE_ENTER, UPDATE_ERASE, UPDATE_WRITE = _p.UPDATE_ENTER, _p.UPDATE_ERASE, _p.UPDATE_WRITE
UPDATE_VERIFY, UPDATE_BOOT, UPDATE_STATUS = _p.UPDATE_VERIFY, _p.UPDATE_BOOT, _p.UPDATE_STATUS
MODE_APP, MODE_BOOTLOADER = 0, 1
VERDICTS = {0: "valid", 1: "no image", 2: "header damaged", 3: "another board's image",
            4: "image does not match its CRC"}
WRITE_REASONS = {1: "damaged on the wire", 2: "outside the slot", 3: "the flash refused",
                 4: "reads back otherwise",  # 4: bootloader version 1 only
                 5: "neither erased nor holding the bytes"}  # 5: version 3 on
NOT_ERASED = 5  # a program step the power cut short: its page is erased and written again
ENTER_OUTPUT_DRIVEN, ENTER_NO_BOOTLOADER = 1, 2  # UpdateEnter's reasons (docs/packets.md)
RETRIES = 3
SWITCH_TIMEOUT_S = 3.0  # a restart: the bootloader's 200 ms window, and the application's start
# The bootloader's check of an image (UpdateVerify, UpdateBoot): a bitwise
# CRC over it, per KB at most (the virtual boards: F103 1.6, G031 2.5,
# F030 3.3 ms/KB; tests/vboard/test_power_cuts.py holds them to this).
CHECK_MS_PER_KB = 4.0


@dataclass
class Status:
    mode: int
    bootloader_version: int
    verdict: int
    version: int
    board: int
    page_size: int
    pages: int
    write_block: int
    largest_write: int


def status(bus, servo_id: int, timeout=None) -> Status:
    return decode_status(bus.request(UPDATE_STATUS, bytes([servo_id]), timeout=timeout))


def decode_status(c: bytes) -> Status:
    """An UpdateStatus answer; BadAnswer for a slot's geometry nothing can
    be written into (no page, no pages, a write block of 0 or above the
    largest write): an update would divide by it or write nowhere."""
    st = Status(*_p.decode_answer(UPDATE_STATUS, c)[1:])
    if st.mode == MODE_BOOTLOADER and not (st.page_size and st.pages and
                                           0 < st.write_block <= st.largest_write):
        raise BadAnswer(f"servo {c[0]}: its bootloader gave a slot no image fits (page size "
                        f"{st.page_size}, {st.pages} pages, write block {st.write_block}, "
                        f"largest write {st.largest_write})")
    return st


def enter_refusal(servo_id: int, reason) -> str:
    """What a refused UpdateEnter means, and what to do about it."""
    if reason == ENTER_OUTPUT_DRIVEN:
        return (f"servo {servo_id} refused to enter its bootloader: its output is driven (a move, "
                f"the wheel, hold or damping), and the restart would let go of any load it holds. "
                f"Support the load, release the servo ('servoctl stop {servo_id}'), then update")
    if reason == ENTER_NO_BOOTLOADER:
        return f"servo {servo_id} has no bootloader: it cannot be updated over the bus"
    return f"servo {servo_id} refused to enter its bootloader (driven, or it has none)"


def _poll_mode(bus, servo_id: int, mode: int, seconds: float, reply_s: float, pause_s: float):
    """UpdateStatus until the servo answers in `mode` (any mode if None);
    the Status, or None after `seconds`."""
    deadline = bus.clock() + seconds
    while bus.clock() < deadline:
        try:
            st = status(bus, servo_id, timeout=reply_s)
            if mode is None or st.mode == mode:
                return st
        except NoReply:
            pass
        bus.sleep(pause_s)
    return None


def _answering(bus, servo_id: int) -> Status:
    """The servo's UpdateStatus once it answers again after a restart it may
    or may not have made (a request whose answer was lost): who answers
    says whether the request was carried out."""
    st = _poll_mode(bus, servo_id, None, SWITCH_TIMEOUT_S, 0.05, 0.02)
    if st is None:
        raise NoReply(f"servo {servo_id}: neither its application nor its bootloader answered "
                      f"within {SWITCH_TIMEOUT_S:.0f} s")
    return st


def check_timeout(bus, size: int) -> float:
    """The wait for an answer that checks an image of size bytes."""
    return bus.timeout + CHECK_MS_PER_KB / 1000 * size / 1024


def _switch(bus, servo_id: int, code: int, packet: str, to_mode: int, refusal, timeout=None) -> Status:
    """UpdateEnter or UpdateBoot, and the servo's Status once it answers in
    to_mode. An answer that is lost is not a failure: the servo answering
    in to_mode shows the request was carried out; in its old mode, that the
    request was lost, and it is sent again."""
    for _ in range(RETRIES):
        try:
            c = _answer(bus.request(code, bytes([servo_id]), timeout=timeout), 2, servo_id, packet)
        except BadAnswer:  # garbled, not lost: nothing to learn by asking again
            raise
        except NoReply:
            st = _answering(bus, servo_id)
            if st.mode == to_mode:
                return st
            continue
        if c[1] != 1:
            raise Refused(refusal(c))
        return _wait_for_mode(bus, servo_id, to_mode)
    raise NoReply(f"servo {servo_id}: no answer to {packet} in {RETRIES} tries")


def _wait_for_mode(bus, servo_id: int, mode: int) -> Status:
    st = _poll_mode(bus, servo_id, mode, SWITCH_TIMEOUT_S, 0.05, 0.02)
    if st is None:
        where = "its bootloader" if mode == MODE_BOOTLOADER else "the new application"
        raise NoReply(f"servo {servo_id}: {where} did not answer within {SWITCH_TIMEOUT_S:.0f} s")
    return st


def catch(bus, servo_id: int, seconds: float) -> Status:
    """Waits up to `seconds` for servo `servo_id`'s bootloader, asking for
    UpdateStatus all the while: power the servo up meanwhile, and its
    bootloader stays for the update (an update packet in its 200 ms window)
    instead of starting an application that may not answer."""
    st = _poll_mode(bus, servo_id, MODE_BOOTLOADER, seconds, 0.02, 0.0)
    if st is None:
        raise NoReply(f"servo {servo_id}: no bootloader answered within {seconds:g} s "
                      "(was it powered up meanwhile?)")
    return st


def _answer(c: bytes, least: int, servo_id: int, packet: str) -> bytes:
    """An update answer with the fields the caller reads, or BadAnswer."""
    if len(c) < least:
        raise BadAnswer(f"servo {servo_id}: an {packet} answer of {len(c)} bytes, not {least} or more")
    return c


def _reason(c: bytes, reasons: dict):
    return reasons.get(c[2], c[2]) if len(c) > 2 else "no reason given"


def _retry(fn):
    """A request lost on the wire is sent again; a refusal is final."""
    for _ in range(RETRIES - 1):
        try:
            return fn()
        except NoReply:
            pass
    return fn()


def _write(bus, servo_id: int, offset: int, chunk: bytes, mend: bool = False) -> bool:
    """True once written; False for a block neither erased nor holding its
    bytes (NOT_ERASED), if mend says the caller mends its page."""
    content = bytes([servo_id]) + struct.pack("<I", offset) + chunk + struct.pack("<I", zlib.crc32(chunk))
    for attempt in range(RETRIES):
        c = _answer(_retry(lambda: bus.request(UPDATE_WRITE, content)), 2, servo_id, "UpdateWrite")
        if c[1] == 1:
            return True
        if mend and c[2:3] == bytes([NOT_ERASED]):
            return False
        if c[2:3] != b"\x01" or attempt == RETRIES - 1:  # 1: damaged on the wire, worth again
            raise Refused(f"servo {servo_id}: writing offset {offset} refused: {_reason(c, WRITE_REASONS)}")
    return True


def _erase(bus, servo_id: int, page: int) -> None:
    c = _answer(_retry(lambda: bus.request(UPDATE_ERASE, bytes([servo_id]) + struct.pack("<H", page))),
                2, servo_id, "UpdateErase")
    if c[1] != 1:
        raise Refused(f"servo {servo_id}: erasing page {page} refused: {_reason(c, WRITE_REASONS)}")


def _write_mending(bus, servo_id: int, data: bytes, offset: int, step: int, page_size: int, done: list):
    """data's step bytes at offset. A block there neither erased nor holding
    its bytes (an update resumed after a power cut in a program step; on the
    G0 a torn double word) is mended: the pages the write touches erased,
    and their blocks written so far (done, offsets) written again, then it."""
    if not _write(bus, servo_id, offset, data[offset:offset + step], mend=True):
        first, last = offset // page_size, (offset + step - 1) // page_size
        for page in range(first, last + 1):
            _erase(bus, servo_id, page)
        lo, hi = first * page_size, (last + 1) * page_size
        for again in [o for o in done if o < hi and o + step > lo] + [offset]:
            _write(bus, servo_id, again, data[again:again + step])
    done.append(offset)


def write_image(bus, servo_id: int, image: Image, st: Status, progress=lambda done, total: None):
    """In the bootloader (st its UpdateStatus): erases the slot's pages,
    writes the image (the header's checked bytes last) and verifies it."""
    if len(image.data) > st.page_size * st.pages:
        if st.verdict == 0:  # nothing erased yet: back to the application
            bus.request(UPDATE_BOOT, bytes([servo_id]), timeout=check_timeout(bus, st.page_size * st.pages))
        raise NotSent(f"the image ({len(image.data)} B) is larger than the slot "
                      f"({st.page_size * st.pages} B)")
    pages = (len(image.data) + st.page_size - 1) // st.page_size
    step = block_bytes(st, bus.serial.baudrate)
    data = image.data + b"\xff" * (-len(image.data) % st.write_block)
    total = pages + len(data)
    for page in range(pages):  # page 0 first: the old image is invalid from here
        _erase(bus, servo_id, page)
        progress(page + 1, total)
    head = -(-CHECKED // step) * step  # the checked header bytes go last
    done = []
    for offset in range(head, len(data), step):
        _write_mending(bus, servo_id, data, offset, step, st.page_size, done)
        progress(min(pages + offset + step, total), total)
    for offset in range(0, head, step):
        _write_mending(bus, servo_id, data, offset, step, st.page_size, done)
    progress(total, total)
    c = _retry(lambda: bus.request(UPDATE_VERIFY, bytes([servo_id]), timeout=check_timeout(bus, len(data))))
    verdict, size, crc, version, _board = _p.decode_answer(UPDATE_VERIFY, c)[1:]
    if verdict != 0 or (size, crc, version) != (image.size, image.crc, image.version):
        raise Refused(f"servo {servo_id}: the written image does not check: {VERDICTS.get(verdict, verdict)}")


# An UpdateWrite frame on the wire at most this long: STOP ALL waits for the
# frame in flight (at 9600 baud 24 bytes of data took 40 ms, a stop 55 ms).
FRAME_MS_MOST = 20
WRITE_OVERHEAD = 14  # an UpdateWrite frame's bytes besides its data: header, ID, offset, CRC, checksum


def block_bytes(st: Status, baud: int) -> int:
    """The data bytes of each UpdateWrite: the most the bootloader takes,
    in whole write blocks, and no more than FRAME_MS_MOST of wire at baud
    (a write block at least)."""
    most = st.largest_write - st.largest_write % st.write_block
    room = int(FRAME_MS_MOST / 1000 * baud / 10) - WRITE_OVERHEAD
    return max(st.write_block, min(most, room - room % st.write_block))


def update(bus, servo_id: int, image: Image, progress=lambda done, total: None) -> tuple:
    """Writes `image` into servo `servo_id` and starts it. Returns the
    version before (None if no application ran) and after."""
    st = status(bus, servo_id)
    if image.board != st.board:  # before anything changes
        raise NotSent(f"servo {servo_id} is {board_named(st.board)}; the image is for "
                      f"{board_named(image.board)}")
    before = st.version if st.mode == MODE_APP or st.verdict == 0 else None
    if st.mode == MODE_APP:
        st = enter_bootloader(bus, servo_id)
    write_image(bus, servo_id, image, st, progress)
    return before, start_application(bus, servo_id, len(image.data)).version


def enter_bootloader(bus, servo_id: int) -> Status:
    """UpdateEnter; the bootloader's Status once it answers."""
    return _switch(bus, servo_id, UPDATE_ENTER, "UpdateEnter", MODE_BOOTLOADER,
                   lambda c: enter_refusal(servo_id, c[2] if len(c) > 2 else None))


def start_application(bus, servo_id: int, size: int = 0) -> Status:
    """UpdateBoot (it checks the image, size bytes if known); the new
    application's Status once it answers."""
    return _switch(bus, servo_id, UPDATE_BOOT, "UpdateBoot", MODE_APP,
                   lambda c: f"servo {servo_id}: the bootloader would not start the image",
                   check_timeout(bus, size))
