"""The wire's timing as the simulator logs it (its control port's `wire`,
on the simulated clock): each servo's CPU takes the target's time for a
main-loop pass, a control tick and an answer (servo_sim --cpu), so the gaps
measured are the firmware's, not the PC's.

A Sync Monitor answer is ready before the servo's turn comes: at 1 Mbaud
the first starts within 2 byte times (20 us) of the request's end while the
line is in use, each later one within 2 of the previous answer's end,
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
AWAKE_AFTER_LINE_US = 4000  # SERVO_AWAKE_AFTER_LINE_US (firmware/app/servo_state.h)
ROUNDS = 60


def wire_spans(sim, count: int = 1024) -> list:
    """(start_us, end_us, bytes, sender) of the wire's latest runs, by their start."""
    spans = []
    for line in sim.control(f"wire {count}").splitlines():
        if line == "end":
            break
        start, end, n, sender = line.split()
        spans.append((int(start), int(end), int(n), sender))
    # In the order they began: a host's burst sent ahead (hostsend) can be
    # logged before the answers on the wire ahead of it.
    return sorted(spans)


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
        round_ms = (len(request) + len(IDS) * 21) * BYTE_US / 1000.0 + 0.5  # and 2 byte times a gap
        # Rounds two at a time, each 37 us later against the 1 kHz control
        # ticks than the last: the rounds meet them at every phase. The
        # second of a pair follows the first's end by about 1.5 ms: the line
        # in use (SERVO_AWAKE_AFTER_LINE_US, 4 ms), however slow this host.
        start_ms = math.ceil(sim.clock_s() * 1000.0) + 1.0
        last_end_ms = start_ms
        sent = 0
        while sent < ROUNDS:
            # Sent ahead by 5 ms (this host's own delays); the second 1 ms
            # after the first's end at the latest, if the first was in time.
            at_ms = max(math.ceil(sim.clock_s() * 1000.0) + 5.0, last_end_ms + 1.0) + (sent * 0.037) % 1.0
            assert sim.control(f"hostsend {at_ms:.3f} {request.hex()}").startswith("ok")
            sent += 1
            if sim.clock_s() * 1000.0 < at_ms and sent < ROUNDS:
                assert sim.control(f"hostsend {at_ms + round_ms + 0.537:.3f} {request.hex()}").startswith("ok")
                sent += 1
            sim.sleep(at_ms / 1000.0 + 2.0 * round_ms / 1000.0 - sim.clock_s())
            for _ in range(100):  # the pair's end: this host may have sent late
                last = wire_spans(sim, 1)[-1]
                if last[3] == str(IDS[-1]) and last[0] >= (at_ms + round_ms) * 1000.0:
                    break
                sim.sleep(0.001)
            last_end_ms = last[1] / 1000.0
        spans = [s for s in wire_spans(sim) if s[0] >= start_ms * 1000.0 - 1]
        gaps, in_use, after_quiet, ratios, rounds, last_end = [], [], [], [], 0, 0
        for i, (start, end, n, sender) in enumerate(spans):
            if sender != "host":
                continue
            answers = spans[i + 1:i + 1 + len(IDS)]
            assert [a[3] for a in answers] == [str(x) for x in IDS], "every servo answers, in turn"
            assert all(a[2] == 21 for a in answers)
            (in_use if start - last_end < AWAKE_AFTER_LINE_US else after_quiet).append(answers[0][0] - end)
            ratios.append((n + 21 * len(IDS)) * BYTE_US / (answers[-1][1] - start))
            gaps += [b[0] - a[1] for a, b in zip(answers, answers[1:])]
            rounds, last_end = rounds + 1, answers[-1][1]
        assert rounds == ROUNDS
        print(f"\n{cpu}: Sync Monitor of {len(IDS)} at 1 Mbaud, {rounds} rounds: gaps "
              f"{min(gaps)}..{max(gaps)} us (mean {sum(gaps) / len(gaps):.1f}); first answer "
              f"{min(in_use)}..{max(in_use)} us after the request in {len(in_use)} rounds on a line in use, "
              f"{min(after_quiet, default=0)}..{max(after_quiet, default=0)} in {len(after_quiet)} "
              f"after 4 ms of quiet; the round at {min(ratios):.3f} of the wire limit at worst")
        assert max(gaps) <= 2 * BYTE_US
        assert min(gaps) >= 0
        # The first answer within 2 byte times of the request's end while the
        # line is in use (the loop awake frames each byte as it lands); after
        # 4 ms of quiet the CPU sleeps, and the USART's IDLE (a byte time
        # after the end) wakes it, unless a tick woke it during the request.
        assert len(in_use) >= ROUNDS // 4
        assert max(in_use) <= 2 * BYTE_US
        # The bus's own share of a robot loop's read: what the firmware leaves
        # of the wire, without the host's.
        assert min(ratios) >= 0.95
    finally:
        finish(sim, IDS)
