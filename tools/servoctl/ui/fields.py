"""The fields of a tab's request to `servoctl ui`'s server, each checked
for its type and range (docs/ui.md, "Malformed requests"): a field of the
wrong type is said back as a malformed request, never taken for another
value ("false" for true, a list for release)."""
import json
import math

ARGV_MAX, ARG_MAX, TAG_MAX = 64, 1024, 64  # argv's words, a word's characters, a tag's


class Malformed(ValueError):
    pass


def parse(data) -> dict:
    """A request: a JSON object of finite numbers. Infinity, NaN and
    nesting deeper than Python's recursion limit are refused as malformed."""
    def no_constant(name):
        raise Malformed(f"{name} is not a number a request may carry")
    try:
        ask = json.loads(data, parse_constant=no_constant)
    except RecursionError:
        raise Malformed("nested too deep") from None
    except UnicodeDecodeError:
        raise Malformed("not UTF-8") from None
    except json.JSONDecodeError as e:
        raise Malformed(f"not JSON: {e}") from None
    if not isinstance(ask, dict):  # [1], 5, "x": not a request
        raise Malformed(f"a request is a JSON object, not {type(ask).__name__}")
    return ask


def mode(value) -> str:
    """A stop's mode: release (also when none is given) or damping."""
    if value is None or (isinstance(value, str) and value in ("release", "damping")):
        return value or "release"
    raise Malformed(f"mode must be 'release' or 'damping', not {value!r:.40}")


def flag(value, name: str) -> bool:
    """true or false, nothing that merely looks true ("false" did)."""
    if not isinstance(value, bool):
        raise Malformed(f"{name} must be true or false, not {value!r:.40}")
    return value


def whole(value, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, str)):
        raise Malformed(f"{name} must be a whole number, not {value!r:.40}")
    return int(value)  # "x" raises ValueError, said as malformed


def servo_id(value, name: str) -> int:
    """A servo's ID, 0..254 (255 is every servo's, which answers nothing):
    refused here, where the tab's tag is still known, not on the bus thread."""
    n = whole(value, name)
    if not 0 <= n <= 254:
        raise Malformed(f"{name}: a servo ID is 0..254, not {n}")
    return n


def number(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise Malformed(f"{name} must be a number, not {value!r:.40}")
    n = float(value)  # "x" raises ValueError, said as malformed
    if not math.isfinite(n):
        raise Malformed(f"{name} must be a finite number, not {value!r:.40}")
    return n


def strings(values, name: str) -> list:
    if not isinstance(values, list) or not all(isinstance(v, (str, int, float)) for v in values):
        raise Malformed(f"{name} must be a list of strings")
    if len(values) > ARGV_MAX:
        raise Malformed(f"{name} has {len(values)} words, over the {ARGV_MAX} a request may have")
    words = [str(v) for v in values]
    if any(len(w) > ARG_MAX for w in words):
        raise Malformed(f"a word of {name} is over the {ARG_MAX} characters a request may have")
    return words


def tag(value):
    """What the page tags a request with, said back with its answers: a
    number or a short string."""
    if value is None or (isinstance(value, int) and not isinstance(value, bool) and abs(value) < 2 ** 53):
        return value
    if isinstance(value, str) and len(value) <= TAG_MAX:
        return value
    raise Malformed(f"tag must be a number or a string of {TAG_MAX} characters at most, not {value!r:.40}")
