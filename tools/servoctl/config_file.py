"""Config and backup files: every item in its engineering unit, written so
it reads back exactly ("135.0 deg", "4000 mW", "75.4 degC", "115200 baud"),
and the servo it came from (ID, model, firmware, serial number), so a file
says what it means and whose it was.

    {"servoctl_config": 2, "servo": {...}, "items": {"angle_max": "135.0 deg", ...},
     "ram_items": {"watchdog_ms": "0 ms", ...}, "ram_items_note": RAM_NOTE}
    {"servoctl_backup": 2, "servos": [{"servo": {...}, "items": {...}}, ...]}

A value with no unit follows the command line's rule (units.py): taken only
where the item has one natural unit. Files in protocol units (a flat
{name: number}, and backups of format 1) still load, marked as raw: a plain
config file only with --raw, since {"angle_max": 45} could mean 45 deg or
the 4.5 deg it is in protocol units.

"ram_items" are this firmware's settable items in RAM (64-72: watchdog,
derating, stream period, jerk limit, oscillation monitor): a dump lists
them so it shows every item a user can set, and config load writes them
back, but the servo keeps them only until it is powered down."""
import json
from dataclasses import dataclass, replace

from . import registers, units
from .errors import NoReply, ServoError
from .protocol import UsageError, ValueOutOfRange

CONFIG_FORMAT = 2
BACKUP_FORMAT = 2
_NAMES = {i.name for i in registers.STORED + registers.RAM}
_RAM = {i.name for i in registers.RAM}
RAM_NOTE = "in RAM: lost at power-up (factory values then); config load sets them again"


@dataclass
class Entry:
    """One servo's user area, and drive area where it has one, as a file holds it."""
    values: dict        # {name: protocol value}, all or some items
    servo: dict = None  # {"id", "model", "firmware", "serial"} when the file says
    raw: bool = False   # the file was in protocol units

    @property
    def serial(self):
        return _number((self.servo or {}).get("serial"))

    @property
    def servo_id(self):
        return (self.servo or {}).get("id")


def _number(value):
    if isinstance(value, str):
        try:
            return int(value, 0)
        except ValueError:
            return None
    return value if isinstance(value, int) and not isinstance(value, bool) else None


def servo_of(s) -> dict:
    """Who a servo is, for a file's "servo" field."""
    return {"id": s.id, "model": s.read("model"), "firmware": f"0x{s.read('firmware'):04x}",
            "serial": f"0x{s.read('serial'):08x}"}


def ram_of(s) -> dict:
    """The servo's RAM items (registers.RAM) it has; none from a servo
    without them (the maker's)."""
    values = {}
    for item in registers.RAM:
        try:
            values[item.name] = s.read(item.id)
        except NoReply:
            raise
        except ServoError:
            continue
    return values


def settable(s) -> dict:
    """Every item a user can set on the servo: stored ones and RAM ones."""
    return dict(s.read_stored(), **ram_of(s))


def save(path: str, s) -> str:
    """config save: the servo's settable items to path; what was saved."""
    values = settable(s)
    write(path, config_json(values, servo_of(s)))
    ram = sum(i.name in values for i in registers.RAM)
    return (f"saved the user area of servo {s.id} to {path}"
            + (f" ({ram} RAM items too: {RAM_NOTE})" if ram else ""))


def entry_json(values: dict, servo: dict) -> dict:
    out = {"servo": servo,
           "items": {i.name: units.exact(i, values[i.name]) for i in registers.STORED if i.name in values}}
    ram = {i.name: units.exact(_in_file(i), values[i.name]) for i in registers.RAM if i.name in values}
    return dict(out, ram_items=ram, ram_items_note=RAM_NOTE) if ram else out


def config_json(values: dict, servo: dict) -> dict:
    return {"servoctl_config": CONFIG_FORMAT, **entry_json(values, servo)}


def backup_json(entries: list) -> dict:
    """entries: [(values, servo)] for each servo."""
    return {"servoctl_backup": BACKUP_FORMAT, "servos": [entry_json(v, s) for v, s in entries]}


def _in_file(item):
    """item as files write it: a RAM item in ms ("500 ms") a time, as the
    user area's are (the command line takes it as a plain number)."""
    ram_ms = item.unit == "ms" and not item.quantity and item.name in _RAM
    return replace(item, quantity="time") if ram_ms else item


def _items(path: str, items, raw: bool) -> dict:
    if not isinstance(items, dict):
        raise UsageError(f"{path}: expected {{name: value}} items")
    unknown = sorted(set(items) - _NAMES)
    if unknown:
        raise UsageError(f"{path}: unknown item(s) {', '.join(unknown)}")
    values = {}
    for name, value in items.items():
        item = _in_file(registers.find(name))
        if not raw and item.quantity == "time" and name in _RAM and str(value).strip().isdigit():
            value = f"{value} ms"  # written before RAM items carried units: ms
        if raw:
            if not isinstance(value, int) or isinstance(value, bool):
                raise UsageError(f"{path}: {name} must be a whole number in protocol units, not {value!r}")
            values[name] = value
        elif isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise UsageError(f"{path}: {name} takes a value with its unit, not {value!r}")
        else:
            try:
                values[name] = units.to_raw(item, str(value))
            except (UsageError, ValueOutOfRange) as e:
                raise type(e)(f"{path}: {e}") from None
    return values


def _values(path: str, entry: dict) -> dict:
    """An entry's items in units, and its RAM items where it has them."""
    return dict(_items(path, entry.get("items"), False), **_items(path, entry.get("ram_items", {}), False))


def parse_config(data, path: str, raw_ok: bool) -> Entry:
    """A config file's contents (already JSON-decoded)."""
    if isinstance(data, dict) and "servoctl_config" in data:
        if data["servoctl_config"] != CONFIG_FORMAT:
            raise UsageError(f"{path}: config format {data['servoctl_config']!r}; this servoctl reads "
                             f"{CONFIG_FORMAT}")
        return Entry(_values(path, data), data.get("servo"))
    if not isinstance(data, dict):
        raise UsageError(f"{path} is not a config file: expected an object")
    if all(isinstance(v, str) for v in data.values()):
        return Entry(_items(path, data, False))  # hand-written, with units
    if not raw_ok:
        raise UsageError(f"{path} holds plain numbers: a raw file in protocol units (angle_max 45 "
                         f"is 4.5 deg there)? Load it with --raw, or write units (\"45 deg\")")
    return Entry(_items(path, data, True), raw=True)


def parse_backup(data, path: str) -> list:
    """A backup's entries; format 1 (protocol units, keyed by ID) is raw."""
    if not isinstance(data, dict) or data.get("servoctl_backup") not in (1, BACKUP_FORMAT):
        raise UsageError(f"{path} is not a servoctl backup")
    servos = data.get("servos")
    if data["servoctl_backup"] == 1:
        if not isinstance(servos, dict) or not all(k.isascii() and k.isdigit() for k in servos):
            raise ValueOutOfRange(f"{path}: no valid servos")
        return [Entry(_items(path, v, True), {"id": int(k)}, raw=True) for k, v in servos.items()]
    if not isinstance(servos, list):
        raise ValueOutOfRange(f"{path}: no valid servos")
    entries = []
    for n, e in enumerate(servos):
        if not isinstance(e, dict) or not isinstance((e.get("servo") or {}).get("id"), int):
            raise ValueOutOfRange(f"{path}: servo entry {n} has no ID")
        entries.append(Entry(_values(path, e), e["servo"]))
    return entries


def read(path: str):
    """A file's JSON; a UsageError naming the file otherwise."""
    try:
        with open(path) as f:
            return json.load(f)
    except OSError as e:
        raise UsageError(f"cannot read {path}: {e.strerror}") from None
    except json.JSONDecodeError as e:
        raise UsageError(f"{path} is not JSON: {e}") from None


def write(path: str, data: dict) -> None:
    try:
        with open(path, "w") as f:
            json.dump(data, f, indent=2)
            f.write("\n")
    except OSError as e:
        raise UsageError(f"cannot write {path}: {e.strerror}") from None
