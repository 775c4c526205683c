"""Several servos at once: a sync move (SyncCommand, one frame for every
listed servo), a broadcast move, async begin and end, Sync Monitor, and the
backup and restore of a whole bus. Angles in degrees, times in seconds."""

from . import protocol as p
from . import config_file, registers, stability
from .frame import check_target
from .errors import BadAnswer, NoReply, NotSent, UsageError
from .checks import MIN_RAMP_MS, check_profile, check_range, scaled, to_ms
from .servo import Monitor, Servo

# A SyncCommand record is its packet's own request (p.encode_request).
MAX_SYNC_RECORDS = 255


def sync_move(bus: p.Bus, targets: dict, duration_s: float, power_w: float = 0.0,
              multi_turn: bool = False) -> None:
    """Every servo in targets ({id: degrees}) starts its move in the same
    frame: single-turn records, or multi-turn ones if multi_turn. Each
    target is checked against its servo first (frame.check_target: one
    frame of reference, the angle limits), and nothing is sent unless all
    pass. No servo answers a sync move (docs/protocol.md)."""
    if not targets or len(targets) > MAX_SYNC_RECORDS:
        raise UsageError(f"a sync move takes 1..{MAX_SYNC_RECORDS} servos, not {len(targets)}")
    multi = multi_turn
    interval = to_ms(duration_s, "duration_s")
    check_profile(MIN_RAMP_MS, MIN_RAMP_MS, interval)  # packets 8 and 13 ramp 20 ms
    power = check_range("power", scaled(power_w, 1000, "power_w"), 0, 65535, "mW")
    if multi:
        code = p.MULTI_TURN
        check_range("interval", interval, *p.field_range(code, "interval"), "ms")
    else:
        code = p.ANGLE
        check_range("interval", interval, *p.field_range(code, "interval"), "ms")
    records = b""
    for servo_id, degrees in targets.items():
        check_range("servo ID", servo_id, 0, p.MAX_ID)
        angle = scaled(degrees, 10, "degrees")
        check_range("angle", angle, *p.field_range(p.MULTI_TURN, "angle"), "deg", 10)
        check_target(Servo(bus, servo_id), angle, multi)
        records += p.encode_request(code, servo_id, angle, interval, power)
    bus.send(p.SYNC, bytes([code, len(records) // len(targets), len(targets)]) + records)


def broadcast_move(bus: p.Bus, degrees: float, duration_s: float, power_w: float = 0.0,
                   ids: list = ()) -> None:
    """Every servo on the bus moves to one single-turn angle; none answers.
    ids are the servos on the bus: each is checked first (frame.check_target:
    in turn 0, the angle within its limits), and nothing is sent unless all
    pass."""
    angle = check_range("angle", scaled(degrees, 10, "degrees"), *p.field_range(p.ANGLE, "angle"), "deg", 10)
    interval = check_range("interval", to_ms(duration_s, "duration_s"), *p.field_range(p.ANGLE, "interval"), "ms")
    check_profile(MIN_RAMP_MS, MIN_RAMP_MS, interval)
    power = check_range("power", scaled(power_w, 1000, "power_w"), 0, 65535, "mW")
    if not ids:
        raise NoReply("no servo on the bus answered: nothing to move")
    for servo_id in ids:
        check_target(Servo(bus, servo_id), angle, False)
    bus.send(p.ANGLE, p.encode_request(p.ANGLE, p.BROADCAST, angle, interval, power))


def begin_async(bus: p.Bus) -> None:
    """From now on every servo buffers its motion commands (up to 8)."""
    bus.send(p.BEGIN_ASYNC, b"")


def end_async(bus: p.Bus, cancel: bool = False) -> None:
    """Every servo starts its buffered commands at once, or drops them."""
    bus.send(p.END_ASYNC, bytes([1 if cancel else 0]))


def sync_monitor(bus: p.Bus, ids: list, timeout_s: float = None, arrivals: dict = None) -> dict:
    """One SyncCommand Monitor: each listed servo answers in list order.
    {id: Monitor} of those that answered; arrivals, if given, gets {id:
    the bus clock when its answer arrived}."""
    bus.send(*monitor_request(ids))
    return monitor_answers(bus, ids, timeout_s, arrivals)


def monitor_request(ids: list) -> tuple:
    """(code, content) of a Sync Monitor of ids, to send alone or in a burst."""
    for servo_id in ids:
        check_range("servo ID", servo_id, 0, p.MAX_ID)
    if not ids or len(ids) > MAX_SYNC_RECORDS:
        raise UsageError(f"a sync monitor takes 1..{MAX_SYNC_RECORDS} servos")
    return p.SYNC, bytes([p.MONITOR, 1, len(ids)] + list(ids))


def monitor_answers(bus: p.Bus, ids: list, timeout_s: float = None, arrivals: dict = None) -> dict:
    """The answers to a Sync Monitor of ids just sent (sync_monitor)."""
    # Each answer is 21 bytes; an absent servo costs 3 ms of silence.
    wait = timeout_s if timeout_s is not None else 0.05 + len(ids) * (0.004 + 210 / bus.serial.baudrate)
    deadline = bus.clock() + wait  # one for the round: the clock is read as little as can be
    out = {}
    waiting = set(ids)
    stamping, bus.stamp_arrivals = bus.stamp_arrivals, arrivals is not None
    try:
        # Answers are taken as they come, whoever sent them: waiting for
        # one absent servo must not throw away the answers of the servos
        # after it, which arrive during that wait.
        while waiting:
            try:
                content = bus.read_response(p.MONITOR, None, deadline=deadline)
            except NoReply:
                break
            servo_id = content[0] if content else None
            if servo_id not in waiting:
                continue  # not asked for in this round: another host's, or a stale one
            try:
                state = Monitor.decode(content)
            except BadAnswer:  # a garbled frame whose checksum held by chance: no state
                continue
            waiting.discard(servo_id)
            out[servo_id] = state
            if arrivals is not None:
                arrivals[servo_id] = bus.arrived_at
    finally:
        bus.stamp_arrivals = stamping
    return {servo_id: out[servo_id] for servo_id in ids if servo_id in out}


def backup(bus: p.Bus, ids: list, path: str) -> None:
    """Every listed servo's user area, in engineering units, with who it is
    (model, firmware, serial), to one file (config_file.py)."""
    entries = []
    for servo_id in ids:
        s = Servo(bus, servo_id)
        entries.append((config_file.settable(s), config_file.servo_of(s)))  # RAM items too
    config_file.write(path, config_file.backup_json(entries))


def id_is_free(bus: p.Bus, servo_id: int, new_id: int) -> None:
    """Refuses to give servo_id the ID new_id when another servo answers
    at new_id: two servos on one ID cannot be told apart again (every
    request to it is answered twice, and collides)."""
    if new_id != servo_id and Servo(bus, new_id).ping():
        raise NotSent(f"ID {new_id} already answers on this bus: servo {servo_id} keeps its ID. "
                      f"Pick a free one ('servoctl scan' lists those in use)")


def write_user_area(s: Servo, values: dict, with_link: bool = False) -> list:
    """Writes values (all or some items, by name) over the servo's own: the
    user area, the drive area where the servo has one, and the RAM items
    (64-72) the values hold. The ID and baud
    rate stay unless with_link: another servo's file must
    not put two servos on one ID; with it, an ID already answering is
    refused, and the ID and baud rate are written last (s then has the new
    ID; the caller sets the bus's rate). Returns the items kept that
    differed."""
    current = s.read_all()
    link = {k: values[k] for k in ("servo_id", "baud") if k in values and values[k] != current[k]}
    if with_link and "servo_id" in link:
        id_is_free(s.bus, s.id, link["servo_id"])
    user = {i.name for i in registers.USER}
    s.write_all(dict(current, **{k: v for k, v in values.items() if k not in link and k in user}))
    drive = [item for item in registers.DRIVE if item.name in values]
    now = s.read_stored() if drive else {}
    changed = {i.name: values[i.name] for i in drive if i.name in now and now[i.name] != values[i.name]}
    # item by item, each a config save (the maker's servos have none); the
    # drive train and gains checked as a set and in an order that stays stable
    s.write_drive({k: v for k, v in changed.items() if k in stability.ITEMS})
    for name, value in changed.items():
        if name not in stability.ITEMS:
            s.write(name, value)
    for item in registers.RAM:  # lost at power-up (config_file.RAM_NOTE)
        if item.name in values:
            s.write(item.name, values[item.name])
    if not with_link:
        return list(link)
    if link:  # last: from here on the servo answers at its new ID and rate only
        s.write_all(dict(s.read_all(), **link))
        s.id = link.get("servo_id", s.id)
    return []


def restore(bus: p.Bus, path: str, with_link: bool = False, set_rate=None) -> tuple:
    """Writes each servo's saved user area back to the servo with that ID
    (every entry checked first). IDs and baud rates stay as they are unless
    with_link; then the host follows: a servo that does not answer at the
    host's rate is looked for at the rates earlier servos were moved to (and
    the rate the restore began at), set_rate(baud) setting the host's.
    Returns (the IDs, {ID: the baud rate it was moved to})."""
    entries = config_file.parse_backup(config_file.read(path), path)
    began, moved = bus.serial.baudrate, {}
    for entry in entries:
        s = Servo(bus, entry.servo_id)
        if with_link and set_rate is not None:
            _reach(s, [*moved.values(), began], set_rate)
        before = s.read("baud") if with_link else None
        write_user_area(s, entry.values, with_link)
        if with_link and entry.values.get("baud", before) != before:
            moved[s.id] = registers.BAUD_RATES[entry.values["baud"]]
    return [entry.servo_id for entry in entries], moved


def _reach(s: Servo, rates, set_rate) -> None:
    """The host at a rate s answers at: its own first, then rates, latest
    first; left at its own if none answers (the write says NoReply)."""
    own = s.bus.serial.baudrate
    for rate in dict.fromkeys([own, *reversed(rates)]):
        if rate != s.bus.serial.baudrate:
            set_rate(rate)
        if s.ping():
            return
    if s.bus.serial.baudrate != own:
        set_rate(own)
