"""A stream's CSV trajectory (servoctl stream FILE): read and checked whole,
every row against every servo's Limits, before anything moves."""
import csv
import math
import re
from dataclasses import dataclass

from .checks import check_range, scaled
from .errors import UsageError, ValueOutOfRange
from .setpoints import MAX_ANGLE_DECIDEG, PERIOD_RANGE_MS, check_ids, check_period


@dataclass
class Trajectory:
    """A CSV trajectory: times (s), {id: [degrees...]}, and each row's line
    in its file, for the messages."""
    times: list
    angles: dict
    lines: list = None
    path: str = ""

    @property
    def period_ms(self) -> int:
        return round((self.times[-1] - self.times[0]) / (len(self.times) - 1) * 1000)

    def where(self, k: int) -> str:
        return f"{self.path} line {self.lines[k]}" if self.lines else f"row {k}"


# How far a row's time may be from the rows' even grid: half a ms, a stamp's
# own rounding (streamed setpoints are stamped in whole ms).
GRID_S = 0.0005 + 1e-9


# A decimal number as a CSV has it: no underscores (Python's float() takes
# 1_0 as 10), no Unicode digits; nan and inf are numbers refused apart.
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|[+-]?(nan|inf|infinity)", re.I)
_ID = re.compile(r"\d+")


def _is_number(cell: str) -> bool:
    return cell.isascii() and _NUMBER.fullmatch(cell.strip()) is not None


def read_trajectory(path: str) -> Trajectory:
    """A CSV: a header of "time" then one servo ID per column; a row per
    setpoint, evenly spaced. Every row is checked, and an error names its
    line: nothing is sent before the whole file has passed."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:  # a BOM is no part of the header
            rows = [(n, r) for n, r in enumerate(csv.reader(f), 1)
                    if r and not r[0].lstrip().startswith("#")]
    except OSError as e:
        raise UsageError(f"cannot read {path}: {e.strerror}") from None
    except (csv.Error, UnicodeDecodeError) as e:
        raise UsageError(f"{path}: not a CSV file ({e}): nothing was sent") from None
    if len(rows) < 3:
        raise UsageError(f"{path}: a header and at least two rows are needed")
    line, header = rows[0]
    if len(header) < 2 or header[0].strip().lower() != "time":
        raise UsageError(f"{path} line {line}: the header is 'time' and servo IDs, separated by commas, not "
                         f"{','.join(header)!r}")
    cell = next((c for c in header[1:] if not (_ID.fullmatch(c.strip()) and c.isascii())), None)
    if cell is not None:
        raise UsageError(f"{path} line {line}: the header is 'time' and servo IDs, not {cell.strip()!r}")
    ids = [int(c) for c in header[1:]]
    try:
        check_ids(ids)
    except UsageError as e:
        raise UsageError(f"{path} line {line}: the header is 'time' and servo IDs ({e})") from None
    table, lines = [], []
    for line, r in rows[1:]:
        def bad(why):
            return UsageError(f"{path} line {line}: {why}; nothing was sent")
        if len(r) != len(ids) + 1:
            raise bad(f"every row has a time and one finite angle per servo ({len(ids)}), not {len(r)} values")
        if not all(map(_is_number, r)):
            cell = next(c for c in r if not _is_number(c))
            raise bad(f"{cell.strip()!r} is not a number: every row has a time (s) and one angle (deg) "
                      f"per servo")
        values = [float(c) for c in r]
        if not all(map(math.isfinite, values)):
            raise bad(f"every row has a time and one finite angle per servo, not {', '.join(r)}")
        for servo_id, degrees in zip(ids, values[1:]):
            try:
                check_range("angle", scaled(degrees, 10, "degrees"), -MAX_ANGLE_DECIDEG, MAX_ANGLE_DECIDEG, "deg", 10)
            except ValueOutOfRange as e:
                raise bad(f"servo {servo_id}'s {e}") from None
        table.append(values)
        lines.append(line)
    times = [r[0] for r in table]
    period = (times[-1] - times[0]) / (len(times) - 1)
    if period <= 0:
        raise UsageError(f"{path}: the times must be evenly spaced and rising; nothing was sent")
    # Times written to the ms (a 30 Hz file's 0.033, 0.067) are on the grid:
    # each within half a ms of it.
    # A time not after the one before names its row; else the first row
    # off the grid of the first and last rows' mean step.
    uneven = [k for k in range(1, len(times)) if times[k] <= times[k - 1]]
    uneven = uneven or [k for k in range(1, len(times)) if abs(times[k] - times[0] - k * period) > GRID_S]
    if uneven:
        k = uneven[0]
        raise UsageError(f"{path} line {lines[k]}: the times must be evenly spaced and rising "
                         f"({period * 1000:.4g} ms apart, from the first and last rows), not "
                         f"{times[k - 1]:g} then {times[k]:g} s; nothing was sent")
    try:
        check_range("period", round(period * 1000), *PERIOD_RANGE_MS, "ms")
    except ValueOutOfRange as e:
        raise ValueOutOfRange(f"{path}: the rows' {e}; nothing was sent") from None
    return Trajectory(times, {servo_id: [r[k + 1] for r in table] for k, servo_id in enumerate(ids)},
                      lines, path)


def row_velocity(times, decideg, k: int) -> float:
    """Row k's velocity as a stream sends it, deg/s: the rows around it (as
    sent, 0.1 deg) over their own times; 0 at the first and last, which a
    stream starts and ends at rest (no motor follows a step of speed)."""
    if k in (0, len(times) - 1):
        return 0.0
    return (decideg[k + 1] - decideg[k - 1]) / 10 / (times[k + 1] - times[k - 1])


def check_trajectory(trajectory: Trajectory, limits: dict) -> None:
    """Every row against every servo's Limits, as Stream checks a send,
    before anything moves: its angle, its step over the rows' own spacing
    and the velocity it is sent with (a file of 2.6 ms rows was checked at
    3 ms, then refused mid-motion); a row outside them is refused with its
    line; the file's period against each servo's bus watchdog first."""
    check_period(limits, trajectory.period_ms, f"{trajectory.path}: " if trajectory.path else "")
    times = trajectory.times
    # Each row's angle and step first (a bad row is named, not the one
    # before it, whose velocity it spoils), then the velocities sent.
    sent = {i: [scaled(degrees, 10, "degrees") for degrees in rows] for i, rows in trajectory.angles.items()}
    for servo_id, rows in sent.items():
        for k, angle in enumerate(rows):
            step_ms = round((times[k] - times[k - 1]) * 1000, 3) if k else 0
            why = limits[servo_id].check(servo_id, angle, rows[k - 1] if k else None, step_ms)
            if why:
                raise ValueOutOfRange(f"{trajectory.where(k)}: {why}; nothing was sent")
    for servo_id, rows in sent.items():
        for k, angle in enumerate(rows):
            why = limits[servo_id].check(servo_id, angle, velocity=scaled(row_velocity(times, rows, k), 10, "velocity"))
            if why:
                raise ValueOutOfRange(f"{trajectory.where(k)}: {why}; nothing was sent")
