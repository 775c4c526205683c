"""The servo's data table (servo-protocol.md 4.2, extensions.md, behaviour.md):
names, sizes, units and ranges, so values are checked before they are sent."""
from dataclasses import dataclass
import struct

from .protocol import ValueOutOfRange


@dataclass(frozen=True)
class Item:
    id: int
    name: str
    size: int
    signed: bool = False
    unit: str = ""
    writable: bool = True
    public: bool = True   # ReadData answers it
    low: int = 0
    high: int = 0
    default: int = 0
    help: str = ""
    quantity: str = ""    # what units.py shows it in: angle, temperature, baud, ...

    def pack(self, value: int) -> bytes:
        fmt = {1: "b", 2: "h", 4: "i"}[self.size]
        return struct.pack("<" + (fmt if self.signed else fmt.upper()), value)

    def unpack(self, data: bytes) -> int:
        fmt = {1: "b", 2: "h", 4: "i"}[self.size]
        return struct.unpack("<" + (fmt if self.signed else fmt.upper()), data)[0]

    def check(self, value: int) -> None:
        if not self.writable:
            raise ValueOutOfRange(f"{self.name} ({self.id}) is read-only")
        if not self.low <= value <= self.high:
            raise ValueOutOfRange(
                f"{self.name} ({self.id}) must be {self.low}..{self.high}{' ' + self.unit if self.unit else ''}, "
                f"not {value}")


U16 = 65535
STATUS = [
    Item(1, "voltage", 2, unit="mV", writable=False),
    Item(2, "current", 2, unit="mA", writable=False),
    Item(3, "power", 2, unit="mW", writable=False),
    Item(4, "temperature", 2, unit="ADC", writable=False, help="NTC ADC value; falls as it heats"),
    Item(5, "status", 1, writable=False),
    Item(6, "model", 2, writable=False),
    Item(7, "firmware", 2, writable=False),
    Item(8, "serial", 4, writable=False),
]
USER = [
    Item(32, "check_flag", 1, low=1, high=1, default=1),
    Item(33, "control_response", 1, low=0, high=1, default=0, help="answer motion when finished"),
    Item(34, "servo_id", 1, low=0, high=254, default=0),
    Item(35, "reserved_35", 1, writable=False, public=False, high=255),
    Item(36, "baud", 1, low=1, high=8, default=5, help="1=9600 ... 5=115200 ... 8=1000000", quantity="baud"),
    Item(37, "stall_release", 1, low=0, high=1, default=0, help="0 limit to stall power, 1 release"),
    Item(38, "stall_power", 2, unit="mW", high=U16, default=10000, quantity="power"),
    Item(39, "low_voltage", 2, unit="mV", high=U16, default=4000, quantity="voltage"),
    Item(40, "high_voltage", 2, unit="mV", high=U16, default=8400, quantity="voltage"),
    Item(41, "temperature_limit", 2, unit="ADC", high=U16, default=651, help="trips at or below", quantity="temperature"),
    Item(42, "power_limit", 2, unit="mW", high=U16, default=10000, quantity="power"),
    Item(43, "current_limit", 2, unit="mA", high=U16, default=4000, quantity="current"),
    Item(44, "start_force", 1, high=255, default=0),
    Item(45, "reserved_45", 1, writable=False, public=False, high=255),
    Item(46, "power_on_lock", 1, low=0, high=1, default=0),
    Item(47, "wheel_brake", 1, low=0, high=1, default=0),
    Item(48, "angle_limit_on", 1, low=0, high=1, default=1),
    Item(49, "soft_start_on", 1, low=0, high=1, default=1),
    Item(50, "soft_start_time", 2, unit="ms", high=U16, default=3000, quantity="time"),
    Item(51, "angle_max", 2, signed=True, unit="0.1deg", low=-1800, high=1800, default=1350, quantity="angle"),
    Item(52, "angle_min", 2, signed=True, unit="0.1deg", low=-1800, high=1800, default=-1350, quantity="angle"),
    Item(53, "center_offset", 2, signed=True, unit="0.1deg", low=-1800, high=1800, default=0, quantity="angle"),
]
USER_AREA_SIZE = sum(item.size for item in USER)  # 32: the WriteBatchData block
ITEMS = STATUS + USER
BY_ID = {i.id: i for i in ITEMS}
BY_NAME = {i.name: i for i in ITEMS}
STATUS_BITS = ["executing", "command_error", "stall", "high_voltage", "low_voltage",
               "over_current", "over_power", "over_temperature"]
BAUD_RATES = {1: 9600, 2: 19200, 3: 38400, 4: 57600, 5: 115200, 6: 250000, 7: 500000, 8: 1000000}


def find(key) -> Item:
    """An item by data ID or name."""
    if isinstance(key, int) or (str(key).isascii() and str(key).isdigit()):
        item = BY_ID.get(int(key))
    else:
        item = BY_NAME.get(str(key))
    if item is None:
        names = ", ".join(i.name for i in ITEMS)
        raise ValueOutOfRange(f"no data item {key!r}; known: {names}")
    return item


def status_names(status: int) -> list:
    return [name for bit, name in enumerate(STATUS_BITS) if status & (1 << bit)]


def encode_user_area(values: dict) -> bytes:
    """The 32-byte block of WriteBatchData from {name: value}; every item
    checked, cross rules included (39 < 40, 51 > 52)."""
    out = b""
    for item in USER:
        value = values[item.name]
        if item.writable:
            item.check(value)
        out += item.pack(value)
    if not values["low_voltage"] < values["high_voltage"]:
        raise ValueOutOfRange("low_voltage (39) must be below high_voltage (40)")
    if not values["angle_max"] > values["angle_min"]:
        raise ValueOutOfRange("angle_max (51) must be above angle_min (52)")
    return out


def decode_user_area(block: bytes) -> dict:
    values, pos = {}, 0
    for item in USER:
        values[item.name] = item.unpack(block[pos:pos + item.size])
        pos += item.size
    return values
