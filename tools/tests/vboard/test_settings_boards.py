"""Settings and plans on the virtual boards: what servoctl says when the
F030's image refuses a value its flash has
no room for (a jerk limit: the Cortex-M0 image has no S-curves), and that
the board's own size-first build is what it names. Time is the board's
simulated time, run ahead while the test waits on it (fast)."""
from servoctl.cli import main
from servoctl.sim import Simulator


def test_the_f030_says_why_it_refuses_a_jerk_limit(tmp_path, capsys):
    sim = Simulator(ids=(1,), tcp=True, state_dir=str(tmp_path / "state"), board="stm32f030k6",
                    fast=True).start()
    try:
        rc = main(["--port", sim.url, "config", "set", "1", "jerk_limit", "5"], clock=sim.clock_s)
        err = capsys.readouterr().err
        assert rc == 1, err
        assert "refused jerk_limit = 5: it runs the Cortex-M0 image (stm32f030k6 (0x0030))" in err, err
        assert "no room for jerk-limited moves (S-curves): 0 only there" in err, err
        assert main(["--port", sim.url, "config", "set", "1", "jerk_limit", "0"], clock=sim.clock_s) == 0
    finally:
        sim.stop()


def test_move_wait_follows_the_f103s_jerk_limited_plan(tmp_path, capsys):
    """The F103's image runs S-curves: 60 deg in 500 ms at 5 (deg/s^2)/ms
    is planned 3012 ms (profile.smooth_window) and arrives in that time."""
    sim = Simulator(ids=(1,), tcp=True, state_dir=str(tmp_path / "state"), board="stm32f103",
                    fast=True).start()
    try:
        for item, value in (("soft_start_on", "0"), ("jerk_limit", "5")):
            assert main(["--port", sim.url, "config", "set", "1", item, value], clock=sim.clock_s) == 0
        capsys.readouterr()
        rc = main(["--port", sim.url, "move", "1", "60", "--interval", "500", "--wait"], clock=sim.clock_s)
        out = capsys.readouterr().out
        assert rc == 0 and "planned 3012 ms" in out, out
        assert 2900 < float(out.split(" after ")[1].split(" ms")[0]) < 4500, out
    finally:
        sim.stop()
