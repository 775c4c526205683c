"""How servoctl says the servo's own faults (kinds 10-15: no readings),
its safe mode (item 75) and its reset counts (item 73), without a servo."""
import signal

import pytest

from servoctl import outcome, registers, units
from servoctl.answers import Fault
from servoctl.errors import Refused, ServoError
from servoctl.fault_code import phrase
from servoctl.cli.cmd_faults import READINGS, _as_json
from servoctl.putback import signals_interrupt


def _fault(what, **readings):
    values = dict(angle_decideg=0x08000123, voltage_mv=0x0201, current_ma=0x0800, power_mw=0x40,
                  winding_decic=1 << 9, case_decic=5)  # a BusFault's frame (PRECISERR) in kind 10's bytes
    values.update(readings)
    return Fault(id=1, count=1, not_logged=0, number=4, op_seconds=60, what=what, **values)


def test_a_fault_with_readings_is_said_with_them():
    f = _fault(3, angle_decideg=900, voltage_mv=8500, current_ma=10, power_mw=5, winding_decic=300,
               case_decic=250)
    assert phrase(f) == "#4 high_voltage at 90.0 deg, 8.50 V, 30 C winding"


def test_a_firmware_fault_is_said_by_its_exception_and_pc_and_a_reset_by_its_kind():
    assert phrase(_fault(10)) == "#4 firmware_fault (BusFault, pc 0x08000123)"
    assert phrase(_fault(10, case_decic=0)) == "#4 firmware_fault (stack guard (main loop), no frame)"
    for what in range(11, 16):
        assert phrase(_fault(what)) == f"#4 {Fault.KINDS[what]}"


def test_the_json_of_the_servos_own_faults_has_no_readings():
    out = _as_json(_fault(10), None)
    assert all(out[name] is None for name in READINGS)
    assert out["code"]["pc"] == 0x08000123 and out["code"]["exception_name"] == "BusFault"
    for what in range(11, 16):
        out = _as_json(_fault(what), None)
        assert all(out[name] is None for name in READINGS) and "code" not in out
    out = _as_json(_fault(3, voltage_mv=8500), None)
    assert out["voltage_mv"] == 8500 and "code" not in out


class _Refusing:
    """A servo whose status says command_error; item 75 as given (None: the
    maker's, which has no item 75)."""

    def __init__(self, status, safe_mode):
        self.id, self.status_byte, self.safe_mode, self.reads = 1, status, safe_mode, []

    def status(self):
        return self.status_byte

    def read(self, name):
        self.reads.append(name)
        if self.safe_mode is None:
            raise ServoError("no data item 75")
        return self.safe_mode


def test_a_move_refused_in_safe_mode_says_so():
    with pytest.raises(Refused) as e:
        outcome.taken(_Refusing(outcome.COMMAND_ERROR, 1), "the move")
    assert "refused the move: it is in safe mode: the output is held off after 3 fault resets" in str(e.value)
    assert "a power cycle or an update ends it" in str(e.value)


@pytest.mark.parametrize("safe_mode", [0, None])
def test_a_move_refused_otherwise_is_said_as_before(safe_mode):
    with pytest.raises(Refused) as e:
        outcome.taken(_Refusing(outcome.COMMAND_ERROR, safe_mode), "the move")
    assert str(e.value) == "servo 1 refused the move (status: command_error)"


def test_a_move_taken_reads_no_item_75():
    s = _Refusing(0, 1)
    assert outcome.taken(s, "the move") == 0 and s.reads == []


def test_reset_counts_are_said_by_name():
    item = registers.find("reset_counts")
    raw = 3 | 1 << 8 | 0 << 16 | 1 << 24
    assert units.show(item, raw) == "3 firmware faults, 1 watchdog, 0 other, 1 brown-out"
    assert units.parts(item, raw) == {"firmware_faults": 3, "watchdog": 1, "other": 0, "brown_out": 1}
    assert units.parts(registers.find("stack_unused"), 7) is None


def test_sigterm_and_sighup_interrupt_inside_and_the_handlers_come_back():
    before = {n: signal.getsignal(n) for n in (signal.SIGTERM, signal.SIGHUP)}
    for number in before:
        with pytest.raises(KeyboardInterrupt) as e:
            with signals_interrupt():
                signal.raise_signal(number)
        assert e.value.args == (signal.Signals(number).name,)
    assert {n: signal.getsignal(n) for n in before} == before


def test_the_firmware_faults_kind_is_the_answers():
    from servoctl import fault_code, fault_symbols
    from servoctl.image import BOARD_MARK_TAG
    assert fault_code.FIRMWARE_FAULT == Fault.FIRMWARE_FAULT and fault_symbols.BOARD_MARK_TAG == BOARD_MARK_TAG
