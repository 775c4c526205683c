"""servoctl finds servo_sim as docs/simulator.md says: $SERVO_SIM, else
the host build of the checkout it is run in (the working directory or a
folder above it), else the PATH; never by where servoctl is installed."""
import pytest

from servoctl.errors import ServoError
from servoctl.sim import HOST_BUILD, find_binary


def test_the_simulator_is_the_host_build_of_the_checkout_servoctl_runs_in(tmp_path, monkeypatch):
    built = tmp_path / "checkout" / HOST_BUILD
    built.parent.mkdir(parents=True)
    built.write_text("")
    inside = tmp_path / "checkout" / "tools" / "somewhere"
    inside.mkdir(parents=True)
    monkeypatch.delenv("SERVO_SIM", raising=False)
    monkeypatch.setenv("PATH", "/nonexistent")
    monkeypatch.chdir(inside)
    assert find_binary() == built
    monkeypatch.setenv("SERVO_SIM", str(tmp_path / "elsewhere"))
    with pytest.raises(ServoError, match="no simulator at .*elsewhere"):
        find_binary()
    monkeypatch.delenv("SERVO_SIM")
    monkeypatch.chdir(tmp_path)  # above the checkout: none
    with pytest.raises(ServoError, match="put servo_sim on the PATH"):
        find_binary()
