"""servoctl stream's host-timing model (--host-jitter-ms, --host-late-every)
is a model for a paced simulator, whose clock moves only while the host
waits: on a simulator in real time (or a servo) its jitter adds to the
PC's own, and a review saw 4-6 deg RMS there without a word. It says so."""
from types import SimpleNamespace

from servoctl.cli.cmd_stream import host_timing


class Bus:
    def __init__(self, paced: bool):
        self.note_sent = (lambda n: None) if paced else None


def test_the_model_on_a_clock_in_real_time_is_said_to_add_to_the_pcs(capsys):
    args = SimpleNamespace(host_jitter_ms=10.0, host_late_every=20)
    assert host_timing(args, Bus(paced=False))
    assert "adds to this PC's own timing" in capsys.readouterr().err
    assert host_timing(args, Bus(paced=True))
    assert capsys.readouterr().err == ""
    assert host_timing(SimpleNamespace(host_jitter_ms=0.0, host_late_every=0), Bus(paced=False)) is None
    assert capsys.readouterr().err == ""  # no model: nothing to say
