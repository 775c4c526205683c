"""A servo whose angle limits are narrower than the factory's is in a
joint, and those limits are its range. The ui's "Angle 0 here" (servoctl
origin) kept the limits' numbers while making the horn's angle 0: a joint
resting 20 deg off zero was then driven 20 deg past its range by an
ordinary move. A wheel ran through the limits without a word. Both now
refuse, nothing done, unless told the horn is free (--past-limits). Time
is the simulator's."""
from servoctl.cli import main
from servoctl.servo import Servo
from servoctl.sim import Simulator

from .joint import narrowed_at_rest


def test_origin_and_wheel_refuse_on_a_joints_limits(tmp_path, capsys):
    with Simulator(ids=[1], state_dir=str(tmp_path / "state"), fast=True) as sim:
        narrowed_at_rest(sim, 1, 200, 200)
        horn = sim.state(1)["angle"]
        for argv, words in ((["origin", "1"], "'servoctl calibrate 1 --past-limits' moves the stored zero"),
                            (["wheel", "1", "run", "--speed", "50"], "If the horn is free, give --past-limits")):
            assert main(["--port", sim.url, *argv], clock=sim.clock_s) == 2, argv
            err = capsys.readouterr().err
            assert "angle limits are on at -20.0..20.0 deg" in err and words in err, err
        sim.sleep(0.5)
        with sim.bus(timeout=0.2) as bus:
            assert abs(Servo(bus, 1).read_motion().angle_decideg - 200) <= 5  # no new origin
        assert abs(sim.state(1)["angle"] - horn) < 0.1  # nothing turned
        assert main(["--port", sim.url, "wheel", "1", "stop"], clock=sim.clock_s) == 0  # a stop always goes
        assert main(["--port", sim.url, "origin", "1", "--past-limits"], clock=sim.clock_s) == 0
        out = capsys.readouterr().out
        assert "now 0.0 deg" in out and "keep their numbers, -20.0..20.0 deg: until power-up they are the horn's old" \
            in out, out
