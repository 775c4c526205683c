"""What servoctl says when the F030's image refuses a value its flash has
no room for (a jerk limit: the Cortex-M0 image has no S-curves), and that
the board's own size-first build is what it names. Time is the board's
simulated time."""
from servoctl.cli import main
from servoctl.sim import Simulator


def test_the_f030_says_why_it_refuses_a_jerk_limit(tmp_path, capsys):
    sim = Simulator(ids=(1,), tcp=True, state_dir=str(tmp_path / "state"), board="stm32f030k6").start()
    try:
        rc = main(["--port", sim.url, "config", "set", "1", "jerk_limit", "5"], clock=sim.clock_s)
        err = capsys.readouterr().err
        assert rc == 1, err
        assert "refused jerk_limit = 5: it runs the Cortex-M0 image (stm32f030k6 (0x0030))" in err, err
        assert "no room for jerk-limited moves (S-curves): 0 only there" in err, err
        assert main(["--port", sim.url, "config", "set", "1", "jerk_limit", "0"], clock=sim.clock_s) == 0
    finally:
        sim.stop()
