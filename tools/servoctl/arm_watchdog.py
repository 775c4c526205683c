"""An arm's bus watchdog (items 64, 65; servoctl.arm): the arm's setting
put on one servo, the servo's own kept first (watchdog_record.py), and
said where what the servo holds is not its own."""
import logging

from .servo import Servo
from .watchdog_record import WatchdogRecords

log = logging.getLogger("servoctl.arm")

WATCHDOG_ACTIONS = {"hold": 0, "damp": 1, "release": 2}  # item 65
DEFAULT = (500, 0)  # the follower's unless told: 500 ms, hold (servoctl.arm.Arm, the plugin's config)


def watchdog_text(setting: tuple) -> str:
    """(watchdog_ms, watchdog_action) as a phrase: '500 ms, hold', 'off'."""
    ms, action = setting
    named = {v: k for k, v in WATCHDOG_ACTIONS.items()}.get(action, f"action {action}")
    return f"{ms} ms, {named}" if ms else f"off ({named})"


def arm_one(s: Servo, who: str, records: WatchdogRecords, ours: tuple):
    """ours on the servo s (who: its joint and ID, for the log); its own
    kept first where it differs. (serial, its own) to put back on close,
    or None where its own is ours."""
    serial = s.read("serial")
    holds = (s.read("watchdog_ms"), s.read("watchdog_action"))
    port = s.bus.port  # a simulator's serials repeat in every simulator: its port tells them apart
    own, found = records.own_setting(serial, holds, [ours, DEFAULT], port)  # the default: another run's
    for said in records.warnings:
        log.warning("%s: %s", who, said)
    records.warnings.clear()
    if found == "record":
        log.warning("%s: its bus watchdog holds %s, which a run that did not end cleanly wrote; its own "
                    "setting, %s (kept in %s), is put back on close", who, watchdog_text(holds),
                    watchdog_text(own), records.path(serial, port))
    elif found == "ours":
        log.warning("%s: its bus watchdog holds %s, the follower's own setting, and no record of the servo's "
                    "own is kept here (%s): a run on another computer, by another user or with another state "
                    "folder that did not end cleanly left it. The power-up setting, %s, is put back on close; "
                    "if %s was set on purpose, set it again after disconnecting ('servoctl config set %d "
                    "watchdog_ms %d')", who, watchdog_text(holds), records.folder, watchdog_text(own),
                    watchdog_text(holds), s.id, holds[0])
    if own != ours:
        records.keep(serial, s.id, own, ours, port)  # before the servo holds ours
    if holds != ours:  # written only where it differs
        s.write("watchdog_ms", ours[0])
        s.write("watchdog_action", ours[1])
    if own == ours and found == "record":
        records.forget(serial, port)  # once the servo holds it: a crash before leaves the record
    return (serial, own) if own != ours else None
