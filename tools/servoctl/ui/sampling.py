"""What `servoctl ui` reads for its Servo and Live plot views, from
servoctl's library: every data item in units (registers, units: the
schema's names, ranges and factory values), and samples of Monitor with
ReadMotion (angle, target, speed, current, power, temperature, the winding's
estimate), stamped with the bus clock at each answer's arrival (the
simulator's clock given --sim-control), as `servoctl monitor` stamps them."""
import math

from .. import registers, units
from ..errors import ServoError
from ..live import _celsius
from ..servo import Servo

NO_MOTION = "the maker's firmware has no ReadMotion (0x40): no target or winding estimate"


def items_of(bus, servo_id: int) -> list:
    """Every public item of one servo: value in units, the text an edit
    starts from (what config set takes back), range, factory value, RAM or
    stored, writable; or why it is missing on this servo."""
    s = Servo(bus, servo_id)
    out = []
    try:
        batch = s.read_all()  # the user area in one ReadBatchData
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
            row.update(raw=raw, value=units.show(item, raw), edit=_edit_text(item, raw))
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
        self.no_motion = set()
        self.last = {}

    def take(self) -> list:
        rows = []
        for servo_id in self.ids:
            s = Servo(self.bus, servo_id)
            try:
                m = s.monitor()
            except ServoError as e:
                rows.append({"id": servo_id, "t": round(self.bus.clock() - self.t0, 4), "silent": str(e)})
                self.last.pop(servo_id, None)
                continue
            t = (self.bus.arrived_at or self.bus.clock()) - self.t0
            angle = m.angle_decideg / 10.0
            row = {"id": servo_id, "t": round(t, 4), "angle": angle, "voltage": m.voltage_mv / 1000.0,
                   "current": m.current_ma / 1000.0, "power": m.power_mw / 1000.0,
                   "temperature": _num(_celsius(m.temperature_adc)),
                   "status": registers.status_names(m.status)}
            before = self.last.get(servo_id)
            self.last[servo_id] = (t, angle)
            row["speed"] = round((angle - before[1]) / (t - before[0]), 1) if before and t > before[0] else None
            if servo_id not in self.no_motion:
                try:
                    r = s.read_motion()
                    row.update(target=r.target_decideg / 10.0, setpoint=r.setpoint_decideg / 10.0,
                               speed=r.velocity_decideg_s / 10.0, winding=r.winding_decic / 10.0,
                               limiter=r.limiter)
                except ServoError:
                    self.no_motion.add(servo_id)
                    row["note"] = NO_MOTION
            rows.append(row)
        return rows
