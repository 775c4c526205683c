"""The servo's data table, from protocol/servo_schema (docs/protocol.md):
names, sizes, units and ranges, so values are checked before they are sent."""
from dataclasses import dataclass
import re
import struct

import servo_schema as schema
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
    names: tuple = ()     # ((value, name), ...): the values the schema's help names
    size_first_max: int = -1  # the most the Cortex-M0 image takes (-1: high); size_first_why says why
    size_first_why: str = ""

    def name_of(self, value: int) -> str:
        """The schema's name for a value ("hold"), or "" where it has none."""
        return dict(self.names).get(value, "")

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


_NAMED = re.compile(r"^(\d+) ([a-z]+)$")


def _names(help_text: str) -> tuple:
    """A help that names values, "0 hold, 1 damp, 2 release" (every part a
    number and one word): ((0, "hold"), ...); () otherwise."""
    parts = [_NAMED.match(part.strip()) for part in help_text.split(",")] if help_text else []
    if not parts or not all(parts):
        return ()
    return tuple((int(m.group(1)), m.group(2)) for m in parts)


def _item(i: schema.Item) -> Item:
    return Item(i.id, i.name, i.size, signed=i.signed, unit=i.unit, writable=i.access == "read-write",
                public=i.access != "reserved", low=i.min, high=i.max, default=i.factory,
                help=i.help, quantity=i.quantity, names=_names(i.help), size_first_max=i.size_first_max,
                size_first_why=_cortex_m0(i.what))


def _cortex_m0(what: str) -> str:
    """The schema's sentence on what the Cortex-M0 image leaves out."""
    return next((part.strip() for part in what.split(". ") if "Cortex-M0" in part), "")


_SCHEMA = schema.load()
STATUS = [_item(i) for i in _SCHEMA.area("status")]
USER = [_item(i) for i in _SCHEMA.area("user")]
USER_AREA_SIZE = sum(item.size for item in USER)  # the WriteBatchData block
FIRMWARE = [_item(i) for i in _SCHEMA.area("firmware")]  # this firmware's own, in RAM
DRIVE = [_item(i) for i in _SCHEMA.area("drive")]  # the drive train and the gains, stored
ITEMS = STATUS + USER + FIRMWARE + DRIVE
STORED = USER + DRIVE  # what the config store keeps, and config files and backups carry
RAM = [i for i in FIRMWARE if i.writable]  # settable, lost at power-up: config dump lists them too
BY_ID = {i.id: i for i in ITEMS}
BY_NAME = {i.name: i for i in ITEMS}
STATUS_BITS = [b.name for b in _SCHEMA.status_bits]
STATUS_MASK = {b.name: 1 << b.bit for b in _SCHEMA.status_bits}  # each status bit's mask, by name
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


# Items the servo keeps in order, each pair (lower, upper): it refuses a
# write that breaks it (registers/data_table.c, cross_item_rules_hold).
ORDERED = (("low_voltage", "high_voltage"), ("angle_min", "angle_max"))


def out_of_order(name: str, value: int, values: dict):
    """Where value of item name breaks its pair's order against values
    ({name: raw}, the other item's at least): (the other's name, "below"
    or "above", what name must stay); None where it keeps it, or name is
    in no pair."""
    for low, high in ORDERED:
        if name == low and not value < values[high]:
            return high, "below"
        if name == high and not value > values[low]:
            return low, "above"
    return None


def pair_of(name: str):
    """The other item of name's pair (ORDERED), or None."""
    return next((b if name == a else a for a, b in ORDERED if name in (a, b)), None)


def encode_user_area(values: dict) -> bytes:
    """The 32-byte block of WriteBatchData from {name: value}; every item
    checked, cross rules included (39 < 40, 51 > 52)."""
    out = b""
    for item in USER:
        value = values[item.name]
        if item.writable:
            item.check(value)
        out += item.pack(value)
    for low, high in ORDERED:
        if not values[low] < values[high]:
            raise ValueOutOfRange(f"{low} ({find(low).id}) must be below {high} ({find(high).id})")
    return out


def decode_user_area(block: bytes) -> dict:
    values, pos = {}, 0
    for item in USER:
        values[item.name] = item.unpack(block[pos:pos + item.size])
        pos += item.size
    return values
