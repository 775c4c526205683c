"""`python -m vboard.bench` (docs/virtual-boards.md, "Speed") runs: it had
stopped at its first board, its runner made without the host link that
the USB adapter's model added, and it counted the answers only as the run
loop hands them over, which the bench does not run. A short run of one
board, every ping answered; its speeds are the bench's figures, not this
test's."""
from vboard import bench


def test_the_bench_runs_every_case_and_hears_every_answer(capsys):
    assert bench.main(["--board", "stm32f030k6", "--seconds", "0.05"]) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert out.count("stm32f030k6") == 3 and "34/34" in out, out
