"""A servo's own bus watchdog setting (items 64, 65), kept on the host
while a host's loop (servoctl.arm: the LeRobot follower) has put its own
there: one file a servo, named by its serial number, written before the
loop's setting goes onto the servo and removed once the servo's own is
back. A servo on a serial device is known by its serial number alone (a
real servo's is its own; the device's name may change when it is plugged
in again); one on a socket:// bus (a simulator: servo_sim gives each
simulator's servos the same serials, 0x51a0UUNN) by its serial and that
port, or one simulator's record would be taken for another's.

A run that ends without putting it back (a closed terminal, a pulled
plug) leaves the loop's setting on the servo and the file on the host.
The next run that finds the servo still holding what the file says was
written, or half of it (a run killed between the two writes: the loop's
ms with the servo's own action, or the servo's own ms with the loop's
action), takes the file's setting as the servo's own, not the value it
reads (its predecessor's), and puts that back when it closes. A servo
that holds anything else has been set since, or power-cycled (items
64-65 are RAM, back to the factory's at power-up): what it holds is its
own, and the file is dropped. A servo that holds exactly the loop's
setting with no file here (another computer's or user's run left it)
is taken to hold the factory's, which is put back (the caller says so).

A file that is not a regular file, or not a record of two settings in
range, is not trusted (dropped, and the caller warns); the files are
written aside without following a link (a new name of our own), then
renamed over. A folder that cannot be written is a RecordError naming it.

The folder: $SERVOCTL_STATE_DIR/watchdog, else $XDG_STATE_HOME/servoctl/
watchdog, else ~/.local/state/servoctl/watchdog."""
import errno
import json
import os
import re
import stat
import tempfile
from pathlib import Path

from .errors import ServoError

FACTORY = (0, 1)  # items 64, 65 at power-up: off, damp
RANGES = ((0, 60000), (0, 2))  # items 64, 65 (docs/protocol.md)


class RecordError(ServoError):
    """The record of a servo's own setting cannot be kept or read: the
    message names the file and what it is for."""


def state_dir() -> Path:
    """servoctl's files that outlive a run (XDG's state, not a cache: a
    lost record would make a loop's setting the servo's own)."""
    if os.environ.get("SERVOCTL_STATE_DIR"):
        return Path(os.environ["SERVOCTL_STATE_DIR"])
    base = os.environ.get("XDG_STATE_HOME") or Path.home() / ".local" / "state"
    return Path(base) / "servoctl"


def _setting(value) -> tuple:
    """A (watchdog_ms, watchdog_action) pair from a record, or ValueError."""
    if not isinstance(value, list) or len(value) != 2 or not all(
            type(v) is int and lo <= v <= hi for v, (lo, hi) in zip(value, RANGES)):
        raise ValueError(f"not a setting: {value!r}")
    return tuple(value)


def _read(path: Path) -> str:
    """The file's text; a FIFO, a device or a folder is not opened for
    reading (it could hang, or be anything)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0))
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise ValueError("not a regular file")
        with os.fdopen(fd, "r", closefd=False) as f:
            return f.read(4096)
    finally:
        os.close(fd)


class WatchdogRecords:
    """Settings are (watchdog_ms, watchdog_action) pairs; serial is the
    servo's serial number (item 8). warnings: what own_setting found not
    to trust, as sentences, for the caller to log."""

    def __init__(self, folder=None):
        self.folder = Path(folder) if folder is not None else state_dir() / "watchdog"
        self.warnings = []

    def path(self, serial: int, port: str = None) -> Path:
        """The record of the servo serial on the bus at port (Bus.port)."""
        where = str(port or "")
        if "://" not in where:  # a serial device: the serial number is the servo's
            return self.folder / f"{serial:08x}.json"
        return self.folder / f"{serial:08x}@{re.sub(r'[^A-Za-z0-9.-]+', '-', where)}.json"

    def own_setting(self, serial: int, holds: tuple, ours=(), port: str = None) -> tuple:
        """(the servo's own setting, where it came from): "record" (the
        path's: the servo holds what the record says a loop wrote, or half
        of it), "ours" (no record, and the servo holds exactly one of ours,
        a list of the settings a loop writes, its own and its default:
        FACTORY is taken), or None (what it holds). port: path's."""
        path = self.path(serial, port)
        holds = tuple(holds)
        try:
            record = json.loads(_read(path))
            own, wrote = _setting(record["own"]), _setting(record["wrote"])
        except FileNotFoundError:
            return (FACTORY, "ours") if holds in ours else (holds, None)
        except (OSError, ValueError, KeyError, TypeError) as e:
            self.warnings.append(f"{path} is not a record of a watchdog setting ({e}): dropped")
            self._drop(path)
            return (FACTORY, "ours") if holds in ours else (holds, None)
        if holds[0] in (own[0], wrote[0]) and holds[1] in (own[1], wrote[1]) and holds != own:
            return own, "record"
        self._drop(path)
        return (FACTORY, "ours") if holds in ours else (holds, None)

    def keep(self, serial: int, servo_id: int, own: tuple, wrote: tuple, port: str = None) -> None:
        """Before the loop's setting (wrote) goes onto the servo: whole on
        disk, or not there (written aside, then renamed over)."""
        path = self.path(serial, port)
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            fd, new = tempfile.mkstemp(prefix=f".{path.name}.", dir=self.folder)  # O_EXCL: no link followed
            try:
                with os.fdopen(fd, "w") as f:
                    json.dump({"servo_id": servo_id, "own": list(own), "wrote": list(wrote)}, f)
                    f.flush()
                    os.fsync(f.fileno())
                os.replace(new, path)
            except BaseException:
                Path(new).unlink(missing_ok=True)
                raise
        except OSError as e:
            raise RecordError(self._cannot("keep", path, e)) from None

    def forget(self, serial: int, port: str = None) -> None:
        """The servo's own setting is back on it."""
        path = self.path(serial, port)
        try:
            path.unlink(missing_ok=True)
        except OSError as e:
            raise RecordError(self._cannot("remove", path, e)) from None

    def _drop(self, path: Path) -> None:
        try:
            path.unlink(missing_ok=True)
        except OSError as e:
            self.warnings.append(self._cannot("remove", path, e))

    def _cannot(self, what: str, path: Path, e: OSError) -> str:
        why = os.strerror(e.errno) if e.errno else str(e)
        return (f"cannot {what} {path}, the record of the servo's own bus watchdog setting while the arm "
                f"holds its own ({why}{'' if e.errno != errno.EACCES else ': not writable by this user'}): "
                f"give a folder this user can write in $SERVOCTL_STATE_DIR, or watchdog_ms=0 to leave the "
                f"watchdog as it is")
