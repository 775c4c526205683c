"""The protocol's one declaration, the TOML files beside this one (frame.toml,
items_*.toml, packets_*.toml), read and checked: the packets, the data items
and the status bits that the firmware's tables (scripts/gen_protocol.py),
servoctl and docs/protocol.md all come from. Standard library only: the
firmware's build runs it with the system's Python, and imports nothing of
servoctl's."""
import dataclasses
import functools
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

SCHEMA = Path(__file__).resolve().parent
# The simulators' control port, beside this folder: not the servo's
# protocol, but declared once for servo_sim and the virtual boards the same way.
CONTROL_PORT = SCHEMA.parent / "control_port.toml"
# No line of the schema's files is longer (scripts/check_layers.py).
LINE_LIMIT = 120
FLAGS = ("addressed", "answers", "answers_if_control_response", "broadcast", "query", "syncable",
         "one_answers", "carries_records")
# The fields of fixed size, by their struct code (lower case: signed).
STRUCT_CODES = {"u8": "B", "u16": "H", "u32": "I", "i16": "h", "i32": "i"}
FIELD_TYPES = {"u8": 1, "u16": 2, "u32": 4, "i16": 2, "i32": 4, "item": None, "user_area": None, "bytes": None}
ITEM_SIZES = (1, 4)  # an item's value: 1 to 4 bytes
ACCESS = ("read", "read-write", "reserved")
FRAME_KEYS = {"request_header", "response_header", "broadcast_id", "max_id", "extended_length",
              "request_content_max", "answer_content_max"}
# Each area's first ID: the maker's data table's two, and this firmware's own.
AREAS = {"status": 1, "user": 32, "firmware": 64, "drive": 80}


class SchemaError(ValueError):
    """The schema says something that cannot be: the sentence says what."""


@dataclass(frozen=True)
class Field:
    name: str
    type: str
    unit: str
    what: str
    limits: tuple = None  # (least, most) the schema gives; None: its type's whole range
    out: str = ""         # a request's value beyond them: "clamp"ed or "refuse"d

    @property
    def range(self) -> tuple:
        """(least, most): the schema's, else the type's (None for a field of varying size)."""
        if self.limits is not None:
            return self.limits
        return _type_range(FIELD_TYPES[self.type], self.type.startswith("i")) if self.type in STRUCT_CODES else None


@dataclass(frozen=True)
class Packet:
    code: int
    name: str       # the protocol's (Ping)
    c: str          # PKT_<c> in C
    py: str         # servoctl's protocol.<py>
    source: str     # maker, extension or firmware
    table: str      # the firmware's packet table its row is in
    flags: tuple
    length: tuple   # (least, most) content bytes
    handler: str    # handle_<handler>(); "" for a packet that carries records
    what: str
    request: tuple
    answer: tuple

    def has(self, flag: str) -> bool:
        return flag in self.flags


@dataclass(frozen=True)
class Item:
    id: int
    area: str
    name: str       # servoctl's and the docs'
    field: str      # the register struct's member
    size: int
    signed: bool
    access: str
    unit: str
    quantity: str
    min: int
    max: int
    factory: int
    what: str
    help: str
    size_first_max: int = -1  # the most a size-first build (the Cortex-M0's) takes; -1: max


@dataclass(frozen=True)
class Control:
    """A command of the simulators' control port."""
    name: str       # its first word
    usage: str      # as help shows it
    value: tuple    # (least, most, unit) of the number it takes, or None
    off: bool       # it also takes the word off
    on: tuple       # the simulators that take it: servo_sim, vboard
    what: str


@dataclass(frozen=True)
class StatusBit:
    bit: int
    name: str
    what: str


@dataclass(frozen=True)
class Schema:
    frame: dict
    status_bits: tuple
    items: tuple
    packets: tuple
    controls: tuple

    def controls_of(self, simulator: str) -> tuple:
        return tuple(c for c in self.controls if simulator in c.on)

    def help_line(self, simulator: str) -> str:
        """What help answers on that simulator's control port."""
        return "ok " + " | ".join(c.usage for c in self.controls_of(simulator))

    def area(self, name: str) -> tuple:
        return tuple(i for i in self.items if i.area == name)

    def packet(self, code: int) -> Packet:
        return next(p for p in self.packets if p.code == code)

    def answer_format(self, code: int):
        """The struct format of a packet's answer (little-endian), or None
        when a field's size varies (an item's value, a block of bytes)."""
        return self._format(self.packet(code).answer)

    def request_format(self, code: int):
        """The same for its request."""
        return self._format(self.packet(code).request)

    def _format(self, fields):
        out = "<"
        for f in fields:
            if f.type == "user_area":
                out += f"{sum(i.size for i in self.area('user'))}s"
            elif f.type in STRUCT_CODES:
                out += STRUCT_CODES[f.type]
            else:
                return None
        return out

    def field(self, code: int, name: str, part: str = "request") -> Field:
        """A field of a packet's request (or answer)."""
        fields = {f.name: f for f in getattr(self.packet(code), part)}
        if name not in fields:
            raise KeyError(f"packet {code:#04x}'s {part} has no field {name!r}: {', '.join(fields)}")
        return fields[name]

    def tables(self) -> dict:
        """{table: its packets, in code order}, tables in the order they first appear."""
        out = {}
        for pkt in self.packets:
            out.setdefault(pkt.table, []).append(pkt)
        return {name: tuple(rows) for name, rows in out.items()}


OUT = ("clamp", "refuse")  # what the servo does with a request's value beyond its field's range


def _fields(where: str, rows, request: bool) -> tuple:
    """A request's or an answer's fields: [name, type, unit, meaning], and
    where the type's range is not the field's, {min, max} (a request's also
    out: clamp or refuse)."""
    out = []
    for row in rows:
        if len(row) not in (4, 5) or row[1] not in FIELD_TYPES:
            raise SchemaError(f"{where}: a field is [name, type, unit, meaning] (and its range) with a type of "
                              f"{', '.join(FIELD_TYPES)}, not {row!r}")
        field = Field(*row[:4])
        if len(row) == 5:
            field = _ranged(f"{where}, field {row[0]}", field, row[4], request)
        out.append(field)
    return tuple(out)


def _ranged(where: str, field: Field, raw, request: bool) -> Field:
    keys = {"min", "max", "out"} if request else {"min", "max"}
    if not isinstance(raw, dict) or set(raw) != keys or field.type not in STRUCT_CODES:
        raise SchemaError(f"{where}: a range is {{{', '.join(sorted(keys))}}} of a number's field, not {raw!r}")
    low, high = field.range
    if not (isinstance(raw["min"], int) and isinstance(raw["max"], int) and low <= raw["min"] <= raw["max"] <= high):
        raise SchemaError(f"{where}: its range needs {low} <= min <= max <= {high}")
    if request and raw["out"] not in OUT:
        raise SchemaError(f"{where}: out is {' or '.join(OUT)}, not {raw['out']!r}")
    return dataclasses.replace(field, limits=(raw["min"], raw["max"]), out=raw.get("out", ""))


def _length(where: str, value) -> tuple:
    if value == "any":
        return (0, 0xFFFF)
    if value is None:
        return None  # the fields' sizes: parse() adds them up once the items are known
    if isinstance(value, int):
        value = [value, value]
    if (not isinstance(value, list) or len(value) != 2 or not all(isinstance(v, int) for v in value)
            or not 0 <= value[0] <= value[1] <= 0xFFFF):
        raise SchemaError(f"{where}: length is a number, [least, most] (0..65535) or \"any\", not {value!r}")
    return tuple(value)


def _type_range(size: int, signed: bool) -> tuple:
    bits = 8 * size
    return (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)


def _item(raw: dict) -> Item:
    where = f"item {raw.get('id')}"
    try:
        item = Item(id=raw["id"], area=raw["area"], name=raw["name"], field=raw["field"], size=raw["size"],
                    signed=raw.get("signed", False), access=raw["access"], unit=raw.get("unit", ""),
                    quantity=raw.get("quantity", ""), min=raw.get("min", 0), max=raw.get("max", 0),
                    factory=raw.get("factory", 0), what=raw["what"], help=raw.get("help", ""),
                    size_first_max=raw.get("size_first_max", -1))
    except KeyError as e:
        raise SchemaError(f"{where}: no {e.args[0]}") from None
    if item.area not in AREAS:
        raise SchemaError(f"{where}: area is one of {', '.join(AREAS)}, not {item.area!r}")
    if item.size not in (1, 2, 4) or item.access not in ACCESS:
        raise SchemaError(f"{where}: size 1, 2 or 4 and access one of {', '.join(ACCESS)}")
    if item.area in ("user", "drive") or (item.area == "firmware" and item.access == "read-write"):
        low, high = _type_range(item.size, item.signed)
        if not low <= item.min <= item.factory <= item.max <= high:
            raise SchemaError(f"{where} ({item.name}): needs {low} <= min <= factory <= max <= {high}")
    elif item.access != "read":
        raise SchemaError(f"{where}: a status item is read-only, a firmware item read or read-write")
    return item


def _packet(raw: dict) -> Packet:
    where = f"packet {raw.get('code')}"
    try:
        c = raw.get("c", re.sub(r"(?<!^)(?=[A-Z])", "_", raw["name"]).upper())  # ResetUserData: RESET_USER_DATA
        pkt = Packet(code=raw["code"], name=raw["name"], c=c, py=raw.get("py", c), source=raw["source"],
                     table=raw["table"], flags=tuple(raw.get("flags", ())),
                     length=_length(where, raw.get("length")), handler=raw.get("handler", ""), what=raw["what"],
                     request=_fields(where, raw.get("request", ()), True),
                     answer=_fields(where, raw.get("answer", ()), False))
    except KeyError as e:
        raise SchemaError(f"{where}: no {e.args[0]}") from None
    unknown = [f for f in pkt.flags if f not in FLAGS]
    if unknown or not 1 <= pkt.code <= 0xFE:
        raise SchemaError(f"{where}: codes are 1..254 and flags {', '.join(FLAGS)} (not {unknown})")
    if pkt.source not in ("maker", "extension", "firmware"):
        raise SchemaError(f"{where}: source is maker, extension or firmware")
    if bool(pkt.handler) == pkt.has("carries_records"):
        raise SchemaError(f"{where}: a handler, or the flag carries_records (the dispatcher runs "
                          f"the records), one of the two")
    return pkt


def content_size(fields, user_area: int):
    """(least, most) bytes of a request's or an answer's fields, or None
    when a block of bytes makes it unknown."""
    least = most = 0
    for f in fields:
        if f.type == "bytes":
            return None
        low, high = ITEM_SIZES if f.type == "item" else (user_area, user_area) if f.type == "user_area" else \
            (FIELD_TYPES[f.type], FIELD_TYPES[f.type])
        least, most = least + low, most + high
    return least, most


def _sized(p: Packet, user_area: int, frame: dict) -> Packet:
    """The packet with its length worked out where the schema leaves it to
    the fields; refused when a request or an answer outgrows the firmware's
    frame buffers."""
    where = f"packet {p.code:#04x} ({p.name})"
    if p.length is None:
        size = content_size(p.request, user_area)
        if size is None or size[0] != size[1]:
            raise SchemaError(f"{where}: give its length: its fields' sizes vary")
        p = dataclasses.replace(p, length=size)
    if p.length[1] != 0xFFFF and p.length[1] > frame.get("request_content_max", 0xFFFF):
        raise SchemaError(f"{where}: a request of {p.length[1]} bytes does not fit the frame's "
                          f"request_content_max ({frame['request_content_max']})")
    answer = content_size(p.answer, user_area)
    if answer is not None and answer[1] > frame.get("answer_content_max", 0xFFFF):
        raise SchemaError(f"{where}: an answer of {answer[1]} bytes does not fit the frame's "
                          f"answer_content_max ({frame['answer_content_max']})")
    return p


def _control(raw: dict) -> Control:
    try:
        value = raw.get("value")
        if value is not None and (len(value) != 3 or not value[0] <= value[1] or not isinstance(value[2], str)):
            raise SchemaError(f"control {raw['usage']!r}: value is [least, most, unit]")
        on = tuple(raw["on"])
        if not on or set(on) - {"servo_sim", "vboard"}:
            raise SchemaError(f"control {raw['usage']!r}: on names servo_sim and/or vboard")
        return Control(raw["usage"].split()[0], raw["usage"], tuple(value) if value else None,
                       raw.get("off", False), on, raw["what"])
    except KeyError as e:
        raise SchemaError(f"a control command has no {e.args[0]}") from None


def _unique(kind: str, values) -> None:
    seen = set()
    for v in values:
        if v in seen:
            raise SchemaError(f"two {kind} {v!r}")
        seen.add(v)


def files() -> tuple:
    """The schema's files, in the order they are read."""
    return tuple(sorted(SCHEMA.glob("*.toml")))


def _merged(texts) -> dict:
    """One schema from its files' texts: the lists (items, packets, status
    bits) of every file one after the other, the tables (frame) key by key."""
    out = {}
    for text in texts:
        for key, value in tomllib.loads(text).items():
            if isinstance(value, list):
                out.setdefault(key, []).extend(value)
            elif isinstance(value, dict) and not set(value) & set(out.setdefault(key, {})):
                out[key].update(value)
            else:
                raise SchemaError(f"{key} is declared twice")
    return out


def parse(text, control_text: str | None = None) -> Schema:
    """The schema from its text (a file's, or a sequence of the files'),
    and the control port's commands from control_text (else from the
    schema's own control key, if any)."""
    try:
        raw = _merged([text] if isinstance(text, str) else text)
        if control_text is not None:
            raw["control"] = raw.get("control", []) + tomllib.loads(control_text).get("control", [])
    except tomllib.TOMLDecodeError as e:
        raise SchemaError(f"not TOML: {e}") from None
    unknown = set(raw) - {"frame", "status_bit", "item", "packet", "control"}
    missing = FRAME_KEYS - set(raw.get("frame", {}))
    if unknown or missing or not raw.get("item") or not raw.get("packet"):
        raise SchemaError(f"the schema has frame (with {', '.join(sorted(FRAME_KEYS))}), status_bit, item and "
                          f"packet, and nothing else (unknown: {sorted(unknown)}, missing from frame: "
                          f"{sorted(missing)})")
    bits = tuple(StatusBit(b["bit"], b["name"], b["what"]) for b in raw.get("status_bit", []))
    items = tuple(sorted((_item(i) for i in raw.get("item", [])), key=lambda i: i.id))
    packets = tuple(sorted((_packet(p) for p in raw.get("packet", [])), key=lambda p: p.code))
    if sorted(b.bit for b in bits) != list(range(len(bits))) or len(bits) > 8:
        raise SchemaError("status bits are 0..7, each once")
    for kind, values in (("item IDs", [i.id for i in items]), ("item names", [i.name for i in items]),
                         ("item fields", [i.field for i in items]), ("packet codes", [p.code for p in packets]),
                         ("packet C names", [p.c for p in packets]), ("packet names", [p.name for p in packets])):
        _unique(kind, values)
    for area, first in AREAS.items():
        ids = [i.id for i in items if i.area == area]
        if ids != list(range(first, first + len(ids))) or (ids and ids[0] != first):
            raise SchemaError(f"the {area} area's items are consecutive IDs from {first}, not {ids}")
    frame = raw.get("frame", {})
    user_area = sum(i.size for i in items if i.area == "user")
    packets = tuple(_sized(p, user_area, frame) for p in packets)
    schema = Schema(frame, bits, items, packets, tuple(_control(c) for c in raw.get("control", [])))
    _unique("control commands", [c.name for c in schema.controls])
    ranges = {}
    for p in packets:  # one handler reads a field of one name and type one way
        for f in p.request:
            if ranges.setdefault((p.handler, f.name, f.type), (f.range, f.out, p.name))[:2] != (f.range, f.out):
                raise SchemaError(f"packet {p.name}: field {f.name} ranges other than in "
                                  f"{ranges[(p.handler, f.name, f.type)][2]}, which handle_{p.handler}() reads too")
    for table, rows in schema.tables().items():
        codes = [p.code for p in rows]
        if codes != list(range(codes[0], codes[0] + len(codes))):
            raise SchemaError(f"packet table {table!r} is a run of consecutive codes, not {codes}")
    return schema


@functools.lru_cache(maxsize=None)
def load() -> Schema:
    return parse([path.read_text(encoding="utf-8") for path in files()],
                 CONTROL_PORT.read_text(encoding="utf-8") if CONTROL_PORT.exists() else None)
