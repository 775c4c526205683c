"""A servo's own bus watchdog setting (items 64, 65), kept on the host
while a host's loop (servoctl.arm: the LeRobot follower) has put its own
there: one file a servo, named by its serial number, written before the
loop's setting goes onto the servo and removed once the servo's own is
back.

A run that ends without putting it back (a closed terminal, a pulled
plug) leaves the loop's setting on the servo and the file on the host.
The next run that finds the servo still holding what the file says was
written takes the file's setting as the servo's own, not the value it
reads (its predecessor's), and puts that back when it closes. A servo
that no longer holds it has been set since, or power-cycled (items 64-65
are RAM, back to the factory's at power-up): what it holds is its own,
and the file is dropped.

The folder: $SERVOCTL_STATE_DIR/watchdog, else $XDG_STATE_HOME/servoctl/
watchdog, else ~/.local/state/servoctl/watchdog."""
import json
import os
from pathlib import Path


def state_dir() -> Path:
    """servoctl's files that outlive a run (XDG's state, not a cache: a
    lost record would make a loop's setting the servo's own)."""
    if os.environ.get("SERVOCTL_STATE_DIR"):
        return Path(os.environ["SERVOCTL_STATE_DIR"])
    base = os.environ.get("XDG_STATE_HOME") or Path.home() / ".local" / "state"
    return Path(base) / "servoctl"


class WatchdogRecords:
    """Settings are (watchdog_ms, watchdog_action) pairs; serial is the
    servo's serial number (item 8)."""

    def __init__(self, folder=None):
        self.folder = Path(folder) if folder is not None else state_dir() / "watchdog"

    def path(self, serial: int) -> Path:
        return self.folder / f"{serial:08x}.json"

    def own_setting(self, serial: int, holds: tuple) -> tuple:
        """(the servo's own setting, the path of the record it came from or
        None): the record's when the servo still holds what the record says
        a loop wrote, else what it holds (a stale record is dropped)."""
        path = self.path(serial)
        try:
            record = json.loads(path.read_text())
            own, wrote = tuple(record["own"]), tuple(record["wrote"])
        except FileNotFoundError:
            return holds, None
        except (ValueError, KeyError, TypeError):
            return holds, None  # not one of ours to trust: the servo's value stands
        if wrote == tuple(holds):
            return own, path
        path.unlink(missing_ok=True)
        return holds, None

    def keep(self, serial: int, servo_id: int, own: tuple, wrote: tuple) -> None:
        """Before the loop's setting (wrote) goes onto the servo: whole on
        disk, or not there (written aside, then renamed over)."""
        self.folder.mkdir(parents=True, exist_ok=True)
        path = self.path(serial)
        new = path.with_name(f".{path.name}.{os.getpid()}")
        with open(new, "w") as f:
            json.dump({"servo_id": servo_id, "own": list(own), "wrote": list(wrote)}, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(new, path)

    def forget(self, serial: int) -> None:
        """The servo's own setting is back on it."""
        self.path(serial).unlink(missing_ok=True)
