"""The wire's timing as the simulator logs it (its control port's `wire`,
on the simulated clock): each servo's CPU takes the target's time for a
main-loop pass, a control tick and an answer (servo_sim --cpu), so the gaps
measured are the firmware's, not the PC's.

A Sync Monitor answer is ready before the servo's turn comes: at 1 Mbaud
each starts within 2 byte times (20 us) of the previous answer's end,
whichever control ticks fall due meanwhile, on both CPUs, and a round of 16
takes the wire limit's time within 5 %."""
import math

import pytest

from servoctl import protocol as p
from servoctl import registers
from servoctl.servo import Servo
from servoctl.sim import Simulator

from .conftest import finish

IDS = list(range(1, 17))
BYTE_US = 10  # at 1 Mbaud
ROUNDS = 60


def wire_spans(sim) -> list:
    """(start_us, end_us, bytes, sender) of the wire's latest runs, oldest first."""
    spans = []
    for line in sim.control("wire 1024").splitlines():
        if line == "end":
            break
        start, end, n, sender = line.split()
        spans.append((int(start), int(end), int(n), sender))
    return spans


@pytest.mark.parametrize("cpu", ["m3", "m0"])
def test_sync_monitor_answers_follow_within_two_byte_times(tmp_path, cpu):
    sim = Simulator(ids=IDS, state_dir=str(tmp_path / "state"), cpu=cpu, paced=True).start()
    try:
        code = {rate: c for c, rate in registers.BAUD_RATES.items()}[1000000]
        with sim.bus() as bus:
            for i in IDS:
                Servo(bus, i).write("baud", code)  # answered at 115200, then it switches
        sim.control("hostbaud 1000000")
        request = p.request_frame(p.SYNC, bytes([p.MONITOR, 1, len(IDS)] + IDS))
        round_ms = (len(request) + len(IDS) * 21) * BYTE_US / 1000.0 + 0.5
        # One round at a time, each 37 us later against the 1 kHz control
        # ticks than the last: the rounds meet them at every phase.
        start_ms = math.ceil(sim.clock_s() * 1000.0) + 2.0
        for k in range(ROUNDS):
            at_ms = math.ceil(sim.clock_s() * 1000.0) + 2.0 + (k * 0.037) % 1.0
            assert sim.control(f"hostsend {at_ms:.3f} {request.hex()}").startswith("ok")
            sim.sleep(at_ms / 1000.0 + round_ms / 1000.0 - sim.clock_s())
        spans = [s for s in wire_spans(sim) if s[0] >= start_ms * 1000.0 - 1]
        gaps, turnarounds, ratios, rounds = [], [], [], 0
        for i, (start, end, n, sender) in enumerate(spans):
            if sender != "host":
                continue
            answers = spans[i + 1:i + 1 + len(IDS)]
            assert [a[3] for a in answers] == [str(x) for x in IDS], "every servo answers, in turn"
            assert all(a[2] == 21 for a in answers)
            turnarounds.append(answers[0][0] - end)
            ratios.append((n + 21 * len(IDS)) * BYTE_US / (answers[-1][1] - start))
            gaps += [b[0] - a[1] for a, b in zip(answers, answers[1:])]
            rounds += 1
        assert rounds == ROUNDS
        print(f"\n{cpu}: Sync Monitor of {len(IDS)} at 1 Mbaud, {rounds} rounds: gaps "
              f"{min(gaps)}..{max(gaps)} us (mean {sum(gaps) / len(gaps):.1f}), first answer "
              f"{min(turnarounds)}..{max(turnarounds)} us after the request; the round at "
              f"{min(ratios):.3f} of the wire limit at worst")
        assert max(gaps) <= 2 * BYTE_US
        assert min(gaps) >= 0
        # The first answer: the USART's IDLE (a byte time), then a pass and
        # the answer's handling on the target's CPU.
        assert min(turnarounds) >= BYTE_US
        # The bus's own share of a robot loop's read: what the firmware leaves
        # of the wire, without the host's.
        assert min(ratios) >= 0.95
    finally:
        finish(sim, IDS)
