"""servoctl faults: a servo's fault history, newest first, and clearing it
(ReadFaults, ClearFaults; docs/safety.md says what a host should do about
each kind)."""
import json
import sys
from dataclasses import asdict

from ..answers import Fault
from ..errors import ServoError
from ..fault_code import FaultCode
from ..fault_symbols import Symbols
from ..outcome import SAFE_MODE, in_safe_mode
from ..servo import Servo

# What a host can do about each kind (docs/safety.md, "Faults").
ADVICE = {
    "stall": "the horn was blocked at its power limit: check the load and the range of motion",
    "high_voltage": "the supply rose above item 40: check the supply (and regenerated power)",
    "low_voltage": "the supply fell below item 39: check the supply and its wiring under load",
    "over_current": "the current passed item 43: check for a short or a jammed gear",
    "over_power": "the power passed item 42: lighten the load or slow the moves",
    "over_temperature": "the case reached item 41: let it cool; lower the duty or the load",
    "watchdog": "the host fell silent for longer than item 64: check the host and the bus",
    "oscillation": "the horn ran or swung away from its setpoint (item 72): check the drive items "
                   "(80-88) against the motor ('servoctl tune'), the encoder and the load",
    "firmware_fault": "the servo's own code faulted: its output went off, it restarted; report it with "
                      "the line above and the image ('servoctl faults ID --elf IMAGE.elf' names the code)",
    "watchdog_reset": "the main loop hung and the watchdog restarted the servo: report it",
    "software_reset": "the servo restarted itself unplanned: report it",
    "brown_out": "the supply dipped below the MCU's reset level: check the supply under load and its wiring",
    "pin_reset": "the reset pin was pulled: check the programming header and the board for noise",
    "low_power_reset": "a low-power reset the firmware never asks for: report it",
}


READINGS = ("angle_decideg", "voltage_mv", "current_ma", "power_mw", "winding_decic", "case_decic")


def _hms(seconds: int) -> str:
    return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


def cmd_faults(bus, args):
    s = Servo(bus, args.id)
    if args.clear:
        s.clear_faults()
        print(f"servo {args.id}: fault history cleared")
        return 0
    symbols = Symbols(args.elf) if args.elf else None
    if symbols is not None:
        _check_board(bus, args.id, symbols, args.elf)
    faults = s.faults()
    first = faults[0] if faults else s.read_fault(0)
    if args.json:
        print(json.dumps({"id": args.id, "not_logged": first.not_logged, "safe_mode": in_safe_mode(s),
                          "faults": [_as_json(f, symbols) for f in faults]}))
        return 0
    if not faults:
        print(f"servo {args.id}: no faults{_not_logged(first.not_logged)}")
        _say_safe_mode(s, "the history was cleared since")
        return 0
    print(f"servo {args.id}: {len(faults)} fault(s), newest first{_not_logged(first.not_logged)}")
    print("   #   op time  fault               supply  current   power  winding     case    angle")
    for f in faults:
        if f.what == Fault.FIRMWARE_FAULT:
            print(f"{f.number:>4} {_hms(f.op_seconds):>9}  {f.kind:<17} {FaultCode.of(f).describe(symbols)}")
        elif f.what > Fault.FIRMWARE_FAULT:  # a reset: no readings
            print(f"{f.number:>4} {_hms(f.op_seconds):>9}  {f.kind:<17}")
        else:
            print(f"{f.number:>4} {_hms(f.op_seconds):>9}  {f.kind:<17} {f.voltage_mv / 1000:>6.2f} V "
                  f"{f.current_ma / 1000:>6.3f} A {f.power_mw / 1000:>5.2f} W {f.winding_decic / 10:>6.1f} C "
                  f"{f.case_decic / 10:>6.1f} C {f.angle_decideg / 10:>7.1f}")
    for kind in dict.fromkeys(f.kind for f in faults):
        print(f"  {kind}: {ADVICE.get(kind, '')}")
    _say_safe_mode(s, "the history above")
    return 0


def _say_safe_mode(s, where: str) -> None:
    if in_safe_mode(s):
        print(SAFE_MODE.format(where=where))


def _check_board(bus, servo_id: int, symbols, path) -> None:
    """Warns where the ELF's board mark is not the servo's board (from
    UpdateStatus); says nothing where either cannot be read."""
    from .. import image, update
    from ..protocol import LinkError
    if symbols.board is None:
        return
    try:
        board = update.status(bus, servo_id).board
    except LinkError:
        raise
    except ServoError:  # no answer, or not one this tool knows (the maker's)
        return
    if board != symbols.board:
        print(f"servoctl: warning: {path} is for {image.board_named(symbols.board)}, servo {servo_id} is "
              f"{image.board_named(board)}: the names given to its code are not its own", file=sys.stderr)


def _not_logged(n: int) -> str:
    return f" ({n} more since power-up not logged: repeats within 10 s, or the wear budget)" if n else ""


def _as_json(f, symbols) -> dict:
    out = dict(asdict(f), kind=f.kind)
    if f.what >= Fault.FIRMWARE_FAULT:  # no readings: a firmware fault's frame (its code) or a reset
        out.update(dict.fromkeys(READINGS))
    if f.what == Fault.FIRMWARE_FAULT:
        code = FaultCode.of(f)
        out["code"] = dict(asdict(code), exception_name=code.exception_name, status_bits=code.status_bits,
                           pc_function=symbols.name(code.pc) if symbols else None)
    return out


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "faults": cmd_faults,
}
