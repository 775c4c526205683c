"""config diff: two user areas side by side, each a servo on the bus, a
config or backup file, or the factory values. A backup holds several
servos: the entry compared is the one with the other side's serial number
when it has one, else the one with its ID."""
import os
from dataclasses import dataclass

from . import config_file, registers, units
from .protocol import UsageError
from .servo import Servo

FACTORY = "factory"


@dataclass
class Side:
    label: str
    values: dict   # {name: protocol value}, all or some items
    serial: int = None
    id: int = None


def _servo_label(servo: dict, fallback: str) -> str:
    serial = config_file._number((servo or {}).get("serial"))
    sid = (servo or {}).get("id")
    who = f"servo {sid}" if sid is not None else fallback
    return f"{who} (serial 0x{serial:08x})" if serial is not None else who


def _from_servo(bus, servo_id: int) -> Side:
    s = Servo(bus, servo_id)
    serial = s.read("serial")
    return Side(f"servo {servo_id} (serial 0x{serial:08x})", s.read_stored(), serial, servo_id)


def _factory() -> Side:
    return Side("factory", {i.name: i.default for i in registers.STORED if i.writable})


def _file_sides(path: str) -> list:
    """Every entry of a config or backup file, as sides."""
    data = config_file.read(path)
    if isinstance(data, dict) and "servoctl_backup" in data:
        entries = config_file.parse_backup(data, path)
    else:
        entries = [config_file.parse_config(data, path, raw_ok=True)]
    return [Side(f"{path}: {_servo_label(e.servo, 'the file')}{' (raw)' if e.raw else ''}",
                 e.values, e.serial, e.servo_id) for e in entries]


def resolve(bus, text: str) -> list:
    """The sides one argument names: an ID, a file, or 'factory'."""
    if text == FACTORY:
        return [_factory()]
    if text.isascii() and text.isdigit():
        return [_from_servo(bus, int(text))]
    if os.path.exists(text):
        return _file_sides(text)
    raise UsageError(f"compare with an ID, a config or backup file, or 'factory', not {text!r}")


def pair(a_sides: list, b_sides: list) -> list:
    """[(a, b)] to compare. One side against many: the one with its serial
    number, else the one with its ID, else each. Many against many: the
    entries whose serial numbers, else IDs, match."""
    if len(a_sides) > 1 and len(b_sides) == 1:
        return [(a, b) for b, a in pair(b_sides, a_sides)]
    if len(a_sides) == 1:
        one = a_sides[0]
        for key in ("serial", "id"):
            same = [b for b in b_sides if getattr(one, key) is not None and getattr(b, key) == getattr(one, key)]
            if same:
                return [(one, b) for b in same]
        return [(one, b) for b in b_sides]
    pairs = []
    for a in a_sides:
        b = next((b for b in b_sides if a.serial is not None and b.serial == a.serial), None) or \
            next((b for b in b_sides if a.id is not None and b.id == a.id), None)
        if b is not None:
            pairs.append((a, b))
    return pairs


def differences(a: Side, b: Side) -> dict:
    """{name: (a, b)} of the items both hold and that differ."""
    return {i.name: (a.values[i.name], b.values[i.name]) for i in registers.STORED
            if i.writable and i.name in a.values and i.name in b.values
            and a.values[i.name] != b.values[i.name]}


def shown(name: str, raw: int) -> str:
    return units.exact(registers.find(name), raw)
