"""The cores skip the main loop's awake passes that find nothing to do
(vboard/idle_skip.py, docs/virtual-boards.md "Skipping an idle pass")
without changing what the wire shows: on a bus of three boards, a Sync
Monitor round and a stream of pings give every byte of every answer at
the same simulated time, to the nanosecond, with skipping on and off, and
the first answer of the round still starts within two byte times. All
times are the simulator's."""
import pytest

from servoctl import protocol as p
from vboard import bench, idle_skip
from vboard.board import elf

from .test_virtual_boards import BOARDS

BYTE_S = 10 / 115200
IDS = (1, 2, 3)


def wire(tmp_path, board: str, skip: bool) -> tuple:
    """Every byte the boards sent, (board, byte, start in ns), and the
    passes skipped."""
    runner = bench.runner_for(board, IDS, str(tmp_path / f"{board}-{skip}"))
    sent = []
    try:
        for b in runner.boards:
            b.core.skip_idle = skip
        skipped = sum(b.core.passes_skipped for b in runner.boards)
        send = runner.bus.send

        def record(station, byte, baud, start_s):
            sent.append((station, byte, round(start_s * 1e9)))
            send(station, byte, baud, start_s)
        runner.bus.send = record
        at_s = runner.now_s + 2e-3
        frames = [p.request_frame(p.SYNC, bytes([p.MONITOR, 1, len(IDS)] + list(IDS)))]
        frames += [p.request_frame(p.PING, bytes([i])) for i in IDS * 4]
        starts = []
        for frame in frames:  # each after the one before has been answered
            starts.append(at_s)
            for byte in frame:
                runner.bus.queue_host(byte, at_s)
            at_s += len(frame) * BYTE_S + (8e-3 if frame is frames[0] else 1.5e-3)
        while runner.now_s < at_s + 2e-3:
            runner.step()
            runner.bus.flush_to_host(runner.now_s)  # the adapter hands the answers over
        skipped = sum(b.core.passes_skipped for b in runner.boards) - skipped
    finally:
        runner.bus.close()
        runner.control.close()
        runner.clock.close()
    request_end_s = starts[0] + len(frames[0]) * BYTE_S
    return sent, skipped, sent[0][2] / 1e9 - request_end_s if sent else None


@pytest.mark.parametrize("board", BOARDS)
def test_skipping_idle_passes_leaves_the_answers_times_as_they_are(tmp_path, board):
    emulated, none, first_gap = wire(tmp_path, board, skip=False)
    skipping, skipped, _ = wire(tmp_path, board, skip=True)
    assert none == 0 and skipped > 1000, skipped
    assert len(emulated) == 3 * 21 + 12 * 6, len(emulated)  # three Monitor answers, twelve pings'
    assert skipping == emulated
    assert 0 < first_gap < 2 * BYTE_S, first_gap * 1e6


def test_a_board_runs_no_further_than_an_instruction_past_its_step(tmp_path):
    """A run stops at the first instruction that reaches its end, not one
    short with a run of a microsecond after it to cross the line (half the
    runs on a busy bus were those)."""
    runner = bench.runner_for("stm32f030k6", (1,), str(tmp_path))
    try:
        core = runner.boards[0].core
        for byte in p.request_frame(p.PING, bytes([1])):
            runner.bus.queue_host(byte, runner.now_s)
        worst, end_s = 0.0, runner.now_s + 3e-3  # the request, the answer, the awake window after
        while runner.now_s < end_s:
            runner.step()
            runner.bus.flush_to_host(runner.now_s)
            worst = max(worst, core.time_s - runner.now_s)
        assert len(runner.bus.to_host) == 6
        assert worst <= core.cpi / core.hz * 1.001, worst * 1e6
    finally:
        runner.bus.close()
        runner.control.close()
        runner.clock.close()


def test_no_pass_is_skipped_in_an_image_other_than_the_elfs(tmp_path):
    """An image that holds servo_poll's bytes where the ELF has them but
    differs elsewhere (an update, a variant: its static data may lie
    otherwise, beyond the _ebss the comparison stops at) skips nothing."""
    runner = bench.runner_for("stm32f103", (1,), str(tmp_path))
    try:
        board = runner.boards[0]
        assert board._pass_start() != 0  # the ELF's own image
        address, size, _ = idle_skip._symbol(idle_skip._elf(elf("stm32f103")), idle_skip.PASS_START)
        at = (address & ~1) + size - board.flash_base  # the code right after servo_poll's
        board.flash_mem.write(at, bytes([board.flash_mem.read(at, 1)[0] ^ 0xFF]))
        assert board._pass_start() == 0
    finally:
        runner.bus.close()
        runner.control.close()
        runner.clock.close()
