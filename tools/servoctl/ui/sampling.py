"""What `servoctl ui` reads for its Servo and Live plot views, from
servoctl's library: every data item in units (registers, units: the
schema's names, ranges and factory values), and samples of Monitor with
ReadMotion (angle, target, speed, current, power, temperature, the winding's
estimate), stamped with the bus clock at each answer's arrival (the
simulator's clock given --sim-control), as `servoctl monitor` stamps them."""
import collections
import math

from .. import group, registers, units
from ..errors import NoReply, ServoError
from ..cli.live import _celsius
from ..servo import Servo

SPEED_BASE_S = 0.05
HEX = {"model", "firmware", "serial"}  # shown as servoctl info shows them
NO_MOTION = "the maker's firmware has no ReadMotion (0x40): no target or winding estimate"


def items_of(bus, servo_id: int) -> list:
    """Every public item of one servo: value in units, the text an edit
    starts from (what config set takes back), range, factory value, RAM or
    stored, writable; or why it is missing on this servo. NoReply if the
    servo answers nothing at all: said once, after one wait, not as every
    item missing from its firmware (a wait for each, 11 s)."""
    s = Servo(bus, servo_id)
    out = []
    try:
        batch = s.read_all()  # the user area in one ReadBatchData
    except NoReply as e:
        if type(e) is NoReply:  # silence, not a garbled answer
            raise NoReply(f"servo {servo_id} does not answer ({e}): is it powered and at this baud rate?") from None
        batch = {}
    except ServoError:
        batch = {}
    for item in registers.ITEMS:
        if not item.public:
            continue
        row = {"id": item.id, "name": item.name, "unit": item.unit, "help": item.help,
               "writable": item.writable, "ram": item in registers.RAM,
               "area": "status" if item in registers.STATUS else "RAM" if item in registers.RAM else "stored",
               "range": f"{units.show(item, item.low)} .. {units.show(item, item.high)}" if item.writable else "",
               "factory": units.show(item, item.default) if item.writable else "",
               "names": [n for _, n in item.names], "m0": item.size_first_why}
        try:
            raw = batch[item.name] if item.name in batch else s.read(item.id)
            shown = f"0x{raw:0{2 * item.size}x}" if item.name in HEX else units.show(item, raw)
            row.update(raw=raw, value=shown, edit=_edit_text(item, raw))
        except ServoError as e:
            row.update(missing=f"not on this servo's firmware: {e}")
        out.append(row)
    return out


def _edit_text(item, raw: int) -> str:
    if item.name_of(raw):
        return item.name_of(raw)
    if item.quantity in units.SCALES or item.quantity in ("temperature", "baud"):
        return units.exact(item, raw).replace(" baud", "")
    return str(raw)


def _num(x):
    return None if x is None or (isinstance(x, float) and math.isnan(x)) else x


class Sampler:
    """Monitor and ReadMotion of each servo in turn, as fast as the bus
    answers; a servo without ReadMotion (the maker's firmware) gives the
    Monitor's half, its speed from two angles."""

    def __init__(self, bus, ids):
        self.bus, self.ids = bus, list(ids)
        self.t0 = bus.clock()
        self.no_motion, self.has_motion = set(), set()
        self.last = {}
        self.silent = {}
        self.rounds = 0

    def take(self) -> list:
        """One round: Monitor of each servo (one Sync Monitor for several),
        then ReadMotion (target, winding, and a lone servo's speed): of a
        lone servo every round; of several, of one in turn every other
        round, their speed from two angles, so that six keep 50 rounds a
        second at 115200 baud."""
        arrivals = {}
        self.rounds += 1
        if len(self.ids) > 1:
            monitors = group.sync_monitor(self.bus, self.ids, arrivals=arrivals)
        else:
            monitors = {}
            try:
                monitors[self.ids[0]] = Servo(self.bus, self.ids[0]).monitor()
                arrivals[self.ids[0]] = self.bus.arrived_at
            except ServoError as e:
                self.silent = {self.ids[0]: str(e)}
        rows = []
        for servo_id in self.ids:
            m = monitors.get(servo_id)
            if m is None:
                why = self.silent.get(servo_id) if len(self.ids) == 1 else None
                rows.append({"id": servo_id, "t": round(self.bus.clock() - self.t0, 4),
                             "silent": why or f"servo {servo_id}: no answer in its Sync Monitor slot"})
                self.last.pop(servo_id, None)
                continue
            rows.append(self._row(servo_id, m, (arrivals.get(servo_id) or self.bus.clock()) - self.t0))
        return rows

    def _row(self, servo_id: int, m, t: float) -> dict:
        angle = m.angle_decideg / 10.0
        row = {"id": servo_id, "t": round(t, 4), "angle": angle, "voltage": m.voltage_mv / 1000.0,
               "current": m.current_ma / 1000.0, "power": m.power_mw / 1000.0,
               "temperature": _num(_celsius(m.temperature_adc)), "status": registers.status_names(m.status)}
        # Speed from two angles SPEED_BASE_S apart at least: 0.1 deg steps
        # between samples 10 ms apart would read 0 or 10 deg/s.
        seen = self.last.setdefault(servo_id, collections.deque())
        seen.append((t, angle))
        while len(seen) > 2 and t - seen[1][0] >= SPEED_BASE_S:
            seen.popleft()
        t0, a0 = seen[0]
        row["speed"] = round((angle - a0) / (t - t0), 1) if t - t0 >= SPEED_BASE_S / 2 else None
        alone = len(self.ids) == 1
        turn = alone or (self.rounds % 2 == 0 and servo_id == self.ids[self.rounds // 2 % len(self.ids)])
        if turn and servo_id not in self.no_motion:
            try:
                r = Servo(self.bus, servo_id).read_motion()
                row.update(target=r.target_decideg / 10.0, setpoint=r.setpoint_decideg / 10.0,
                           winding=r.winding_decic / 10.0, limiter=r.limiter)
                if alone:  # the servo's own speed; of several, every round's from two angles
                    row["speed"] = r.velocity_decideg_s / 10.0
                self.has_motion.add(servo_id)
            except ServoError:
                if servo_id not in self.has_motion:  # never answered it: not a lost answer
                    self.no_motion.add(servo_id)
                    row["note"] = NO_MOTION
        return row
