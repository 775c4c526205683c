"""An update's UpdateWrite frames are short enough on the wire that STOP
ALL, which waits for the frame in flight, goes out soon: at 9600 baud 24
bytes of data were a 40 ms frame, and a stop took up to 55 ms."""
from servoctl.update import FRAME_MS_MOST, WRITE_OVERHEAD, Status, block_bytes


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
