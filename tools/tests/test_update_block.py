"""An update's UpdateWrite frames are short enough on the wire that STOP
ALL, which waits for the frame in flight, goes out soon: at 9600 baud 24
bytes of data were a 40 ms frame, and a stop took up to 55 ms."""
import struct

import pytest

from servoctl.update import FRAME_MS_MOST, WRITE_OVERHEAD, BadAnswer, Status, block_bytes, decode_status


def status(write_block: int, largest: int = 24) -> Status:
    return Status(mode=1, bootloader_version=1, verdict=0, version=1, board=1, page_size=1024, pages=24,
                  write_block=write_block, largest_write=largest)


def test_a_slow_baud_rate_takes_shorter_blocks():
    assert block_bytes(status(4), 115200) == 24  # the bootloader's most: 38 bytes, 3.3 ms
    assert block_bytes(status(4), 1000000) == 24
    at_9600 = block_bytes(status(4), 9600)
    assert at_9600 == 4 and (at_9600 + WRITE_OVERHEAD) * 10 / 9600 * 1000 <= FRAME_MS_MOST
    assert block_bytes(status(8), 9600) == 8  # a write block at least, however slow
    assert block_bytes(status(8, largest=20), 115200) == 16  # whole write blocks


def test_a_slot_no_image_fits_is_a_bad_answer():
    """A bootloader's UpdateStatus with a write block of 0 made the update
    divide by it (a traceback); any geometry nothing can be written into is
    a one-line BadAnswer before anything is sent."""
    def answer(page_size, pages, write_block, largest):  # the layout of docs/packets.md, 0x55
        return struct.pack("<BBHBHHHHBH", 1, 1, 2, 0, 16, 49, page_size, pages, write_block, largest)

    assert decode_status(answer(2048, 25, 8, 24)).write_block == 8
    for bad in [(2048, 25, 0, 24), (0, 25, 8, 24), (2048, 0, 8, 24), (2048, 25, 8, 4)]:
        with pytest.raises(BadAnswer, match="gave a slot no image fits"):
            decode_status(answer(*bad))
