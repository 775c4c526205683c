"""IDs by serial number: AssignId (0x42, docs/packets.md) reaches the one
servo with a serial number whatever its ID, so two servos on one ID can be
told apart, and a bus of new servos (all at the factory ID) can be numbered
one servo at a time."""

from . import protocol as p
from . import scan
from .errors import NotSent
from .protocol import NoReply, Refused, UsageError
from .servo import Servo


def serial_number(text: str) -> int:
    """A serial number as scan and info print it (0x51a00003) or decimal."""
    try:
        value = int(text, 0)
    except ValueError:
        raise UsageError(f"not a serial number: {text!r} (scan and info show them, e.g. 0x51a00003)") from None
    if not 0 <= value <= 0xFFFFFFFF:
        raise UsageError(f"a serial number is 32 bits, not {text}")
    return value


def assign(bus: p.Bus, serial: int, new_id: int) -> None:
    """Gives the servo with this serial number the ID new_id, durably.
    Refused, before anything is sent, when another servo answers at
    new_id."""
    if not 0 <= new_id <= p.MAX_ID:
        raise UsageError(f"servo IDs are 0..{p.MAX_ID}, not {new_id}")
    holder = scan.probe(bus, new_id, scan.reply_window_s(bus.serial.baudrate))
    if holder is not None and serial not in holder.serials:
        raise NotSent(f"ID {new_id} already answers on this bus ({holder.describe()}): pick a free one")
    bus.send(p.ASSIGN_ID, p.encode_request(p.ASSIGN_ID, p.BROADCAST, serial, new_id))
    try:
        answer = bus.read_response(p.ASSIGN_ID, None)
    except NoReply:
        raise NoReply(f"no servo with serial 0x{serial:08x} answered AssignId (0x42): is it on the "
                      f"bus, at this baud rate, with this firmware?") from None
    if len(answer) != 2:
        raise p.BadAnswer(f"an AssignId answer of {len(answer)} bytes, not 2")
    if answer[1] != 1:
        s = Servo(bus, answer[0])
        raise Refused(f"servo serial 0x{serial:08x} (ID {answer[0]}) refused ID {new_id}{s._why_refused()}")


def bring_up(bus: p.Bus, from_id: int, first_id: int, count: int, wait_s: float, say) -> list:
    """Numbers new servos: each servo answering at from_id (the factory ID)
    whose serial number is known gets the next free ID from first_id on.
    Several new servos on the bus at once answer together and their
    answers collide (on a real wire and on the simulators' alike): say()
    asks for one at a time, and the error at the deadline says why.
    Returns [(serial, id)]."""
    window = scan.reply_window_s(bus.serial.baudrate)
    done = []
    next_id = first_id
    while len(done) < count:
        deadline = bus.clock() + wait_s
        found = None
        asked = collided = False  # each said once a servo: a user reads it, not a log
        while found is None:
            if bus.clock() > deadline:
                why = (f" (two or more answer there at once, and their answers collide: connect "
                       f"one new servo at a time)") if collided else ""
                raise NoReply(f"no servo alone at ID {from_id} within {wait_s:g} s{why}; "
                              f"{len(done)} numbered")
            f = scan.probe(bus, from_id, window)
            if f is not None and f.mode == "application" and f.serials and f.serials_complete:
                found = f  # alone, or several whose serial numbers all came through
            elif f is not None and f.shared:
                if not collided:
                    say(f"two or more servos answer at ID {from_id} and their answers collide: "
                        f"connect one new servo at a time")
                collided = True
                bus.heard = True  # answers came at this rate, garbled: no rate hint at the deadline
                bus.sleep(1.0)
            else:
                if not asked and not collided:
                    say(f"connect new servo {len(done) + 1} of {count} (it answers at ID {from_id}) ...")
                asked = True
                bus.sleep(0.2)
        while next_id == from_id or scan.probe(bus, next_id, window) is not None:
            next_id += 1
            if next_id > p.MAX_ID:
                raise Refused(f"no free ID left from {first_id} on")
        serial = found.serials[0]
        assign(bus, serial, next_id)
        done.append((serial, next_id))
        say(f"servo serial 0x{serial:08x} is now ID {next_id}")
        next_id += 1
    return done
