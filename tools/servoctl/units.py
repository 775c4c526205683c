"""Data items in engineering units: what the user types and reads. Each
item's quantity (registers.py) says how its raw protocol value is shown and
which units it takes.

A plain number is taken only where the item has one natural unit (an angle
in deg, a temperature in degC, a baud rate, a count); where two are common
(V and mV, A and mA, W and mW, s and ms) the unit must be written, since
"2.5" meant 2 mW to someone who meant 2.5 W. A value the wire cannot carry
exactly is refused with the nearest ones it can, never rounded silently.

    angle        0.1 deg on the wire; deg ("90", "90deg", "-45.5°")
    temperature  NTC ADC on the wire; degC ("75", "75C", "75degC"), or the ADC ("651ADC")
    voltage      mV ("7400mV", "7.4V")
    current      mA ("4000mA", "4A")
    power        mW ("2500mW", "2.5W")
    time         ms ("3000ms", "3s")
    baud         the index 1..8 on the wire; the rate ("115200", "1000000baud")
    (none)       a whole number in the item's own unit, if it has one, written
                 with it in files ("2741 mOhm", "2786 x 0.1 uN m"), taken
                 with it or bare (items 70, 80-91)
"""
import math
import re

from . import ntc, registers
from .protocol import UsageError, ValueOutOfRange

# quantity: (unit shown, {suffix: factor to the raw unit})
SCALES = {
    "voltage": ("mV", {"mv": 1, "v": 1000}),
    "current": ("mA", {"ma": 1, "a": 1000}),
    "power": ("mW", {"mw": 1, "w": 1000}),
    "time": ("ms", {"ms": 1, "s": 1000}),
    "angle": ("deg", {"": 10, "deg": 10, "°": 10}),
}
# How a suffix is written (the user's may be in any case).
_SPELLING = {"mv": "mV", "v": "V", "ma": "mA", "a": "A", "mw": "mW", "w": "W", "ms": "ms", "s": "s",
             "deg": "deg", "°": "°"}
_NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z°]*)\s*$")


def _split(item, text: str):
    m = _NUMBER.match(str(text))
    if not m:
        raise UsageError(f"{item.name} takes a number{_units_hint(item)}, not {text!r}")
    value = float(m.group(1))
    if not math.isfinite(value):
        raise UsageError(f"{item.name} takes a finite number, not {text!r}")
    return value, m.group(2).lower()


def _units_hint(item) -> str:
    if item.names:
        return f" (or {', '.join(name for _, name in item.names)})"
    if item.quantity in SCALES:
        return " in " + " or ".join(_SPELLING[s] for s in SCALES[item.quantity][1] if s)
    return {"temperature": " in degC", "baud": " (a baud rate)"}.get(item.quantity, "")


def to_raw(item, text) -> int:
    """The protocol value for what the user typed; range-checked, with the
    range said in the same units. A value the schema names ("hold") is
    taken by its name too."""
    named = {name: value for value, name in item.names}
    if str(text).strip().lower() in named:
        return named[str(text).strip().lower()]
    value, suffix = _split(item, _own_unit_off(item, str(text)))
    q = item.quantity
    if q in SCALES:
        shown, factors = SCALES[q]
        if suffix not in factors:
            if suffix == "":
                both = " or ".join(f"{value:g}{_SPELLING[s]}" for s in factors)
                raise UsageError(f"{item.name} takes a unit: {text!r} could mean {both}")
            raise UsageError(f"{item.name} takes a number{_units_hint(item)}, not {text!r}")
        raw = _exact(item, value, factors[suffix], text)
    elif q == "temperature" and suffix == "adc":  # the NTC's ADC value itself: exact
        if value != int(value):
            raise UsageError(f"{item.name} takes a whole ADC value, not {text!r}")
        raw = int(value)
    elif q == "temperature":
        if suffix not in ("", "c", "degc", "°c"):
            raise UsageError(f"{item.name} takes degC (or the NTC's ADC value, '651ADC'), not {text!r}")
        if not -40 <= value <= 150:
            raise ValueOutOfRange(f"{item.name} ({item.id}) must be -40..150 degC, not {value:g}")
        raw = ntc.celsius_to_adc(value)
    elif q == "baud":
        rates = {rate: code for code, rate in registers.BAUD_RATES.items()}
        if suffix not in ("", "baud") or value not in rates:
            raise ValueOutOfRange(f"{item.name} ({item.id}) must be one of "
                                  f"{', '.join(str(r) for r in rates)}, not {text!r}")
        raw = rates[value]
    else:
        if suffix or value != int(value):
            own = f" (of {item.unit})" if item.unit else ""
            raise UsageError(f"{item.name} takes a whole number{own}, not {text!r}")
        raw = int(value)
    if not item.low <= raw <= item.high:
        raise ValueOutOfRange(f"{item.name} ({item.id}) must be {show(item, item.low)}.."
                              f"{show(item, item.high)}, not {text}")
    return raw


def _own_unit_off(item, text: str) -> str:
    """text without the item's own unit at its end ("2741 mOhm"), for an
    item of no quantity that has one: how files write it (exact)."""
    unit = item.unit if not item.quantity else ""
    bare = text.strip()
    if unit and bare.lower().endswith(unit.lower()) and len(bare) > len(unit):
        head = bare[:-len(unit)].rstrip()
        return head[:-1] if unit[0].isdigit() and head.endswith("x") else head
    return text


def _exact(item, value: float, factor: int, text) -> int:
    """value x factor as a whole raw number, or a refusal naming the two
    nearest values the wire can carry."""
    scaled = value * factor
    raw = round(scaled)
    if abs(scaled - raw) > 1e-6 * max(1.0, abs(scaled)):
        low, high = math.floor(scaled), math.ceil(scaled)
        raise ValueOutOfRange(f"{item.name} ({item.id}) is set in steps of {show(item, 1)}: {text} "
                              f"would be rounded; give {show(item, low)} or {show(item, high)}")
    return raw


def exact(item, raw: int) -> str:
    """raw in the item's unit, written so that to_raw gives raw back: what
    config and backup files hold ("135.0 deg", "4000 mW", "75.3 degC")."""
    q = item.quantity
    if q == "angle":
        return f"{raw / 10:.1f} deg"
    if q in SCALES:
        return f"{raw} {SCALES[q][0]}"
    if q == "temperature":
        try:
            celsius = ntc.adc_to_celsius(raw)
        except ValueError:
            celsius = None
        for places in (1, 2, 3, 4):
            if celsius is not None and -40 <= round(celsius, places) <= 150 \
                    and ntc.celsius_to_adc(round(celsius, places)) == raw:
                return f"{celsius:.{places}f} degC"
        return f"{raw} ADC"
    if q == "baud":
        return f"{registers.BAUD_RATES[raw]} baud"
    if item.unit:  # a unit that is a number itself is a multiple: "300 x 0.1 uN m"
        return f"{raw} {'x ' if item.unit[0].isdigit() else ''}{item.unit}"
    return str(raw)


def show_as_typed(item, text, raw: int) -> str:
    """raw in the unit text was typed in ("20V": "20 V"); as show() says it
    where text has no unit of its own or the item one unit only."""
    m = _NUMBER.match(str(text))
    suffix = m.group(2).lower() if m else ""
    factors = SCALES.get(item.quantity, ("", {}))[1]
    if item.quantity == "angle" or not suffix or suffix not in factors:
        return show(item, raw)
    return f"{raw / factors[suffix]:g} {_SPELLING[suffix]}"


# Item 73's bytes, lowest first (docs/protocol.md): each a count since power-on.
RESET_COUNTS = ("firmware faults", "watchdog", "other", "brown-out")


def parts(item, raw: int):
    """{name: value} of an item whose bytes are separate counts (73
    reset_counts), for --json; None for every other item."""
    if item.name != "reset_counts":
        return None
    return {name.replace(" ", "_").replace("-", "_"): raw >> 8 * i & 0xFF for i, name in enumerate(RESET_COUNTS)}


def show(item, raw: int) -> str:
    """A raw protocol value in the item's engineering unit, for people: a
    temperature with its ADC value, a baud rate with its code, item 73's
    four counts by name."""
    q = item.quantity
    if item.name == "reset_counts":
        return ", ".join(f"{raw >> 8 * i & 0xFF} {name}" for i, name in enumerate(RESET_COUNTS))
    if q == "temperature":
        return ntc.describe(raw)
    if q == "baud":
        return f"{registers.BAUD_RATES.get(raw, '?')} baud (code {raw})"
    shown = exact(item, raw) if q in SCALES else f"{raw}{' ' + item.unit if item.unit else ''}"
    return f"{shown} ({item.name_of(raw)})" if item.name_of(raw) else shown
