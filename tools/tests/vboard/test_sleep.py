"""The shipped images sleep (WFI) when a pass has nothing to do
(docs/sleep.md), on both boards: an idle board's CPU is asleep nearly all
the time, a request that arrives while it sleeps is still answered within
two byte times of its last stop bit, and the answer goes out by DMA with
one interrupt at its end. All times are the simulator's."""
import pytest

from servoctl import protocol as p

from .test_virtual_boards import BOARDS, start

BYTE_S = 10 / 115200


@pytest.mark.parametrize("board", BOARDS)
def test_an_idle_board_sleeps_and_answers_within_two_byte_times(tmp_path, board):
    sim = start(tmp_path, board)
    try:
        before = sim.state(1)
        sim.sleep(0.3)
        after = sim.state(1)
        slept = (after["asleep_ms"] - before["asleep_ms"]) / (after["sim_ms"] - before["sim_ms"])
        assert slept > 0.9, f"asleep {slept:.0%} of the time with nothing to do"
        for _ in range(3):  # at three phases of the control tick
            at_s = sim.clock_s() + 0.05 + _ * 0.00033
            ping = p.request_frame(p.PING, bytes([1]))
            assert sim.control(f"hostsend {at_s * 1000:.3f} {ping.hex()}").startswith("ok")
            sim.sleep(at_s + 0.01 - sim.clock_s())
            answer_starts_s = sim.state(1)["last_sent_ms"] / 1000 - 5 * BYTE_S  # six bytes back to back
            request_ends_s = at_s + len(ping) * BYTE_S
            assert 0 < answer_starts_s - request_ends_s < 2 * BYTE_S, (answer_starts_s - request_ends_s) * 1e6
        # The answer goes out by DMA: the USART interrupts once for the
        # request (IDLE) and once for the answer (TC), not once a byte; or
        # once for both, when the main loop, awake at its tick as the
        # request ends, answers before the line's IDLE (the G0 here: IDLEIE
        # is off while it sends, and TC's handler finds IDLE set too).
        before = sim.state(1)["usart_interrupts"]
        at_s = sim.clock_s() + 0.05
        assert sim.control(f"hostsend {at_s * 1000:.3f} {ping.hex()}").startswith("ok")
        sim.sleep(at_s + 0.01 - sim.clock_s())
        assert 1 <= sim.state(1)["usart_interrupts"] - before <= 2
    finally:
        sim.stop()
