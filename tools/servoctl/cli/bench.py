"""How close servoctl comes to the wire: Sync Monitor rounds a second, and
the time of a firmware update, each against the limit the wire (and, for
an update, the flash) sets, computed from the packets' sizes. Times are
the bus's clock: the simulator's own on the simulator, the host's on a
real port."""
from dataclasses import dataclass

from .. import group
from .. import protocol as p
from .. import update as upd

BITS_PER_BYTE = 10  # start, 8 data, stop
FRAME_OVERHEAD = 5  # header 2, packet number, content length, checksum
MONITOR_ANSWER = 16  # content bytes of a Monitor answer (docs/protocol-packets.md)
# The STM32F1 flash's slowest page erase and half-word program (datasheet
# DS5319, tERASE and tPROG maximum), which the simulator models too
# (hal/ports/host/sim_flash.h).
FLASH_ERASE_S = 0.040
FLASH_PROGRAM_S = 70e-6


@dataclass
class Figure:
    what: str
    measured: float  # per second (a rate) or seconds (a time)
    limit: float     # the same, as the wire (and flash) allow at best
    unit: str

    @property
    def ratio(self) -> float:
        """Of the limit: rounds measured / possible, or floor / time taken."""
        if self.unit == "s":
            return self.limit / self.measured
        return self.measured / self.limit

    def line(self) -> str:
        return (f"{self.what}: {self.measured:.3g} {self.unit}, limit {self.limit:.3g} {self.unit}: "
                f"{self.ratio:.2f} of the wire's best")


def wire_s(n_bytes: int, baud: int) -> float:
    return n_bytes * BITS_PER_BYTE / baud


def sync_monitor_rounds(bus: p.Bus, ids: list, seconds: float) -> Figure:
    """Sync Monitor rounds of all ids, back to back, for `seconds` of the
    bus clock; a round counts when every servo answered."""
    request = FRAME_OVERHEAD + 3 + len(ids)
    answers = len(ids) * (FRAME_OVERHEAD + MONITOR_ANSWER)
    limit = 1.0 / wire_s(request + answers, bus.serial.baudrate)
    start = bus.clock()
    rounds = 0
    while bus.clock() - start < seconds:
        if len(group.sync_monitor(bus, ids)) == len(ids):
            rounds += 1
    took = bus.clock() - start
    return Figure(f"Sync Monitor of {len(ids)} servos at {bus.serial.baudrate} baud", rounds / took,
                  limit, "rounds/s")


def update_floor_s(image: upd.Image, st: upd.Status, baud: int) -> float:
    """The least an update can take: its packets on the wire, both ways,
    and the flash's erases and programs."""
    pages = -(-len(image.data) // st.page_size)
    step = st.largest_write - st.largest_write % st.write_block
    size = len(image.data) + (-len(image.data) % st.write_block)
    writes = -(-size // step)
    wire = pages * (FRAME_OVERHEAD + 3 + FRAME_OVERHEAD + 3)  # UpdateErase and its answer
    wire += writes * (2 * FRAME_OVERHEAD + 1 + 4 + 4 + 3) + size  # UpdateWrite: id, offset, crc; answer
    wire += FRAME_OVERHEAD + 1 + FRAME_OVERHEAD + 14  # UpdateVerify and its answer
    flash = pages * FLASH_ERASE_S + size // 2 * FLASH_PROGRAM_S
    return wire_s(wire, baud) + flash


def update_time(bus: p.Bus, servo_id: int, image: upd.Image) -> Figure:
    """Updates servo_id with image; the time from the first erase to the
    verified image, against the floor for the same packets and flash
    work. The restarts into the bootloader and back are left out."""
    st = upd.status(bus, servo_id)
    if st.mode == upd.MODE_APP:
        st = upd.enter_bootloader(bus, servo_id)
    floor = update_floor_s(image, st, bus.serial.baudrate)
    start = bus.clock()
    upd.write_image(bus, servo_id, image, st)
    took = bus.clock() - start
    upd.start_application(bus, servo_id)
    return Figure(f"update of {len(image.data)} B at {bus.serial.baudrate} baud", took, floor, "s")


def image_of_size(size: int, version: int, board: int) -> upd.Image:
    """A stand-in image of `size` code bytes, for the simulator, whose slot
    holds bytes it never executes."""
    from .. import image as img

    code = bytes((i * 7 + (i >> 8)) & 0xFF for i in range(size))
    return img.parse(img.build(code, version, board))

