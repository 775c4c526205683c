"""The shipped images sleep (WFI) when a pass has nothing to do
(docs/sleep.md), on every board: an idle board's CPU is asleep nearly all
the time, a request that arrives while it sleeps is still answered within
two byte times of its last stop bit, and the answer goes out by DMA with
one interrupt at its end. All times are the simulator's."""
import pytest

from servoctl import protocol as p

from .test_virtual_boards import BOARDS, start

BIT_S = 1 / 115200
BYTE_S = 10 * BIT_S
IDLE_S = 10.5 * BIT_S  # IDLE: a whole idle frame after the last stop bit (vboard/usart.py)
# The F1's driver keeps IDLEIE on while it sends (hal/ports/stm32f1/usart_hd.c);
# the F0's, which the G0 runs too (usart_v2_hd.c), turns it off with the receiver.
IDLEIE_WHILE_SENDING = {"stm32f103": True, "stm32f030k6": False, "stm32g031k8": False}


@pytest.mark.parametrize("board", BOARDS)
def test_an_idle_board_sleeps_and_answers_within_two_byte_times(tmp_path, board):
    sim = start(tmp_path, board)
    try:
        before = sim.state(1)
        sim.sleep(0.3)
        after = sim.state(1)
        slept = (after["asleep_ms"] - before["asleep_ms"]) / (after["sim_ms"] - before["sim_ms"])
        assert slept > 0.9, f"asleep {slept:.0%} of the time with nothing to do"
        ping = p.request_frame(p.PING, bytes([1]))
        ahead_of_idle = []
        for phase in range(8):  # at eight phases of the 1 ms control tick
            interrupts = sim.state(1)["usart_interrupts"]
            at_s = sim.clock_s() + 0.05 + phase * 0.000125
            assert sim.control(f"hostsend {at_s * 1000:.3f} {ping.hex()}").startswith("ok")
            sim.sleep(at_s + 0.01 - sim.clock_s())
            state = sim.state(1)
            answer_starts_s = state["last_sent_ms"] / 1000 - 5 * BYTE_S  # six bytes back to back
            gap_s = answer_starts_s - (at_s + len(ping) * BYTE_S)
            assert 0 < gap_s < 2 * BYTE_S, gap_s * 1e6
            # The answer goes out by DMA: not an interrupt a byte. Asleep
            # through the request, the loop is woken by its IDLE and the
            # answer's TC ends it: two. Woken by a tick within the request,
            # the loop stays awake while the line is in use and answers
            # before the IDLE: the F1 still takes IDLE on its own, the F0
            # and G0 (IDLEIE off while sending) clear it in TC's handler: one.
            ahead = gap_s < IDLE_S
            ahead_of_idle.append(ahead)
            expected = 1 if ahead and not IDLEIE_WHILE_SENDING[board] else 2
            assert state["usart_interrupts"] - interrupts == expected, (phase, gap_s * 1e6)
        assert any(ahead_of_idle) and not all(ahead_of_idle), "both ways a request meets the loop"
    finally:
        sim.stop()
