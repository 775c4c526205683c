"""Who is on the bus: for each ID, whether anything answers, whether it is
an application or a bootloader waiting for an image, and whether one ID is
held by two servos (their answers arrive twice, or collide and arrive
garbled). A collision on the wire cannot be avoided, only noticed: every
probe keeps listening for its whole window."""
import struct
from dataclasses import dataclass, field

from . import protocol as p
from . import registers
from . import update
from .protocol import BadAnswer, NoReply

_SERIAL = registers.find("serial")
_BAUD = registers.find("baud")
ANSWER_MAX_BYTES = 21  # UpdateStatus's answer, the longest a probe asks for


def reply_window_s(baud: int) -> float:
    """How long to listen after a request: the request and a short answer
    (12 bytes, 10 bits a byte) and 3 ms for the servo and the link to turn
    around. IDs 0-254 take about a second at 115200."""
    return 12 * 10 / baud + 0.003


@dataclass
class Found:
    id: int
    baud: int
    mode: str = "application"  # or "bootloader": no application runs
    verdict: str = ""          # a bootloader's word on the image in its slot
    serials: list = field(default_factory=list)  # every serial number heard at this ID
    answers: int = 1           # good answers to one Ping
    garbled: int = 0           # answers that arrived damaged

    @property
    def shared(self) -> bool:
        """Two or more servos hold this ID."""
        return self.answers > 1 or len(self.serials) > 1 or self.garbled > 0

    @property
    def serials_complete(self) -> bool:
        """Every servo at this ID told its serial number: none garbled."""
        return self.garbled == 0 and len(self.serials) >= self.answers

    @property
    def servos(self) -> int:
        """How many servos hold this ID, as far as their answers tell."""
        return max(1, self.answers, len(self.serials), 2 if self.shared else 1)

    def describe(self) -> str:
        where = f"servo {self.id} at {self.baud} baud"
        if self.shared and len(self.serials) > 1:
            return (f"{where}: TWO OR MORE SERVOS hold this ID (serials "
                    f"{', '.join(f'0x{s:08x}' for s in self.serials)}). Give one a free ID by its "
                    f"serial number: 'servoctl id assign 0x{self.serials[-1]:08x} N'")
        if self.shared:
            return (f"{where}: TWO OR MORE SERVOS hold this ID ({self.answers} good and "
                    f"{self.garbled} garbled answers). Connect them one at a time to learn their "
                    f"serial numbers ('servoctl scan'), then 'servoctl id assign SERIAL N'")
        if self.mode == "bootloader":
            return (f"{where}: in its bootloader, no application runs ({self.verdict}): "
                    f"'servoctl update {self.id} IMAGE' installs one")
        serial = f", serial 0x{self.serials[0]:08x}" if self.serials else ""
        return f"{where}{serial}"

    def as_json(self) -> dict:
        return {"id": self.id, "baud": self.baud, "mode": self.mode, "serials": self.serials,
                "shared": self.shared}


def count_line(found: list) -> str:
    """scan's last line: servos, not IDs (a new bus holds them all at ID 0)."""
    if not found:
        return "no servo answered"
    n = sum(f.servos for f in found)
    at_least = any(f.shared and not f.serials_complete for f in found)
    return f"{'at least ' if at_least else ''}{n} servo(s) found"


# A page erase's longest (DS5319: 40 ms), docs/decisions-hardware.md.
ERASE_MAX_S = 0.04


def wake(bus: p.Bus) -> None:
    """Before a sweep: a servo in a page erase answers nothing (it begins
    one once released and quiet for 0.1 s), and a sweep asks each ID once.
    A Ping to broadcast, which no servo answers, ends the quiet, so no
    erase begins for 0.1 s; one already running is waited out. The sweep's
    requests then follow each other closer than 0.1 s."""
    bus.send(p.PING, bytes([p.BROADCAST]))
    bus.sleep(ERASE_MAX_S + 0.005)


def probe(bus: p.Bus, servo_id: int, window_s: float):
    """What answers at servo_id (a Found), or None if nothing does."""
    pings, garbled, stray = bus.gather(p.PING, bytes([servo_id]), window_s)
    if not pings and not garbled and not stray:
        return None
    found = Found(servo_id, bus.serial.baudrate, answers=len(pings), garbled=garbled + (stray > 0))
    # The next requests listen long enough for a whole answer (21 bytes at
    # most) from every servo the Ping heard, and from one more than that
    # (two at least): the servos at one ID answer one after another, and a
    # late answer must not run into the next request's. A bus of four new
    # servos sends 84 bytes of UpdateStatus answers, 7.3 ms at 115200.
    servos = max(2, len(pings) + garbled + 1)
    window_s += servos * ANSWER_MAX_BYTES * 10 / bus.serial.baudrate
    statuses, bad, stray = bus.gather(update.UPDATE_STATUS, bytes([servo_id]), window_s)
    found.garbled += bad + (stray > 0)
    try:
        st = update.decode_status(statuses[0]) if statuses else None
    except BadAnswer:
        st = None  # another firmware's
    if st is not None and st.mode == update.MODE_BOOTLOADER:
        found.mode = "bootloader"
        found.verdict = update.VERDICTS.get(st.verdict, f"verdict {st.verdict}")
        return found  # a bootloader answers no ReadData
    answers, bad, stray = bus.gather(p.READ_DATA, bytes([servo_id, _SERIAL.id]), window_s)
    found.garbled += bad + (stray > 0)
    for content in answers:
        if len(content) == 2 + _SERIAL.size:
            found.serials.append(struct.unpack_from("<I", content, 2)[0])
        else:
            found.garbled += 1
    if str(getattr(bus, "port", "")).startswith("socket://") and not found.shared:
        # A TCP link's baudrate is pyserial's, not the wire's (the far end
        # sets that, e.g. hostbaud): the servo's own item 36 is the truth.
        answers, _, _ = bus.gather(p.READ_DATA, bytes([servo_id, _BAUD.id]), window_s)
        if len(answers) == 1 and len(answers[0]) == 2 + _BAUD.size:
            found.baud = registers.BAUD_RATES.get(answers[0][2], found.baud)
    return found


def in_bootloader(bus: p.Bus, servo_id: int):
    """Why a servo that does not answer as an application may be silent:
    a sentence if its bootloader answers instead, else None."""
    try:
        st = update.status(bus, servo_id)
    except NoReply:
        return None
    if st.mode != update.MODE_BOOTLOADER:
        return None
    return (f"servo {servo_id} is in its bootloader, not its application (its slot: "
            f"{update.VERDICTS.get(st.verdict, st.verdict)}): 'servoctl update {servo_id} IMAGE' "
            f"installs an application")
