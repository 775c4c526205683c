"""What a host sees after the servo's own faults, on both virtual boards
(the shipped images, vboard/inject.py's faults through the control port,
the bus through servoctl on the simulated clock): the fault history names
the fault and, with the image's ELF, the function that faulted; item 73
counts the resets; the servo then answers the maker's packets and moves
as before; three fault resets in a row leave it in safe mode (item 75),
answering with its output off, until a power-on."""
import pytest

from servoctl.answers import Fault
from servoctl.fault_code import FaultCode
from servoctl.fault_symbols import Symbols
from servoctl.servo import Servo
from vboard.board import elf

from .test_virtual_boards import BOARDS, start

EXCEPTION = {"bus": {True: 5, False: 3}, "undef": {True: 6, False: 3}}
FUNCTION = {"bus": "dma_rx_sync"}  # the main loop's read of the receive DMA's counter (inject.py)


@pytest.fixture(params=BOARDS)
def board(request):
    return request.param


def back_in_application(sim, servo):
    """Waits (simulated time) for the restart, then for the servo's answer
    and its fault record's write (a half-word a control tick)."""
    for _ in range(40):
        sim.sleep(0.05)
        if sim.state(1)["mode"] == "app" and servo.ping():
            sim.sleep(0.05)
            return
    raise AssertionError("the servo did not come back")


def fault_reset(sim, servo, what: str) -> dict:
    """Injects what, waits for the reset it ends in (simulated time) and
    for the servo back: the state as the reset left it."""
    before = sim.state(1)
    assert sim.control(f"inject 1 {what}").startswith("ok")
    for _ in range(100):
        sim.sleep(0.01)
        state = sim.state(1)
        if state["last_reset_ms"] != before["last_reset_ms"]:
            break
    else:
        raise AssertionError(f"no reset after inject {what}")
    back_in_application(sim, servo)
    return state


@pytest.mark.parametrize("what", ["bus", "undef"])
def test_a_fault_is_named_then_the_servo_is_itself_again(tmp_path, board, what):
    sim = start(tmp_path, board)
    try:
        servo = Servo(sim.bus(timeout=0.3), 1)  # a page erase after the restart stalls the servo 20-40 ms
        servo.write("soft_start_on", 0)
        servo.move(450, interval_ms=300)
        sim.sleep(0.4)
        state = fault_reset(sim, servo, what)
        v7m = board == "stm32f103"
        assert state["bridge_off_at_ms"] - state["fault_at_ms"] <= (0.005 if v7m else 0.010)
        newest = servo.read_fault(0)
        assert newest.what == Fault.FIRMWARE_FAULT and newest.kind == "firmware_fault"
        code = FaultCode.of(newest)
        assert code.exception == EXCEPTION[what][v7m]
        name = Symbols(elf(board)).name(code.pc)
        assert name is not None and (what not in FUNCTION or name.startswith(FUNCTION[what]))
        assert servo.read("reset_counts") == 1 and servo.read("safe_mode") == 0
        # The maker's packets, as its SDK sends them: a ping, a read, a move.
        assert servo.ping() and -180.0 <= servo.position_deg() <= 180.0
        servo.move(-300, interval_ms=300)
        sim.sleep(0.5)
        assert servo.position_deg() == pytest.approx(-30.0, abs=0.3)
    finally:
        sim.stop()


def test_a_hang_and_a_brownout_are_in_the_history(tmp_path, board):
    sim = start(tmp_path, board)
    try:
        servo = Servo(sim.bus(timeout=0.3), 1)
        servo.write("soft_start_on", 0)
        fault_reset(sim, servo, "hang")
        assert sim.state(1)["resets_watchdog"] == 1
        assert servo.read_fault(0).kind == "watchdog_reset"
        assert sim.control("brownout 1 5").startswith("ok")
        back_in_application(sim, servo)
        assert [f.kind for f in servo.faults()] == ["brown_out", "watchdog_reset"]
        assert servo.read("reset_counts") == 0x01000100  # a brown-out, a watchdog reset
    finally:
        sim.stop()


def test_three_in_a_row_leave_it_answering_with_the_output_off(tmp_path, board):
    sim = start(tmp_path, board)
    try:
        servo = Servo(sim.bus(timeout=0.3), 1)
        servo.write("soft_start_on", 0)
        for what in ("bus", "undef", "bus"):
            fault_reset(sim, servo, what)
        assert servo.read("safe_mode") == 1 and servo.read("reset_counts") == 3
        assert [f.kind for f in servo.faults()] == ["firmware_fault"] * 3
        servo.move(600, interval_ms=200)
        sim.sleep(0.5)
        assert sim.state(1)["current"] == 0 and abs(servo.position_deg()) < 1.0
        assert servo.read("limiter") == 7  # a monitor holds it: ReadFaults says which
        assert sim.control("powercycle 1").startswith("ok")
        back_in_application(sim, servo)
        assert servo.read("safe_mode") == 0
        servo.move(600, interval_ms=200)
        sim.sleep(0.5)
        assert servo.position_deg() == pytest.approx(60.0, abs=0.3)
    finally:
        sim.stop()
