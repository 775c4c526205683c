"""The simulators' control port is declared once (protocol/control_port.toml):
servo_sim and a virtual board list the commands the schema gives each, and
answer the same line the same way: a value out of its declared range, off
where only stop takes it, an unknown command."""
import pytest

import servo_schema as schema
from servoctl.errors import ServoError
from servoctl.sim import Simulator

LINES = ["supply 30001", "load -50.5", "hostbaud 1100", "stop off", "supply off", "supply x", "supply",
         "failerase -1", "nosuch", "nosuch 3"]


@pytest.fixture(scope="module")
def answers(tmp_path_factory):
    """{simulator: [its answer to each line of LINES, then to help]}."""
    out = {}
    for name, board in (("servo_sim", None), ("vboard", "stm32f103")):
        state = tmp_path_factory.mktemp(name)
        with Simulator(ids=[1], state_dir=str(state), board=board) as sim:
            out[name] = [_said(sim, line) for line in LINES + ["help"]]
    return out


def _said(sim, line: str) -> str:
    """The reply, an error's as the simulator wrote it."""
    try:
        return sim.control(line).rstrip("\n")
    except ServoError as e:
        return str(e)[str(e).index("error: "):]


@pytest.mark.parametrize("simulator", ["servo_sim", "vboard"])
def test_help_lists_the_commands_the_schema_gives_the_simulator(answers, simulator):
    assert answers[simulator][-1] == schema.load().help_line(simulator)


def test_both_simulators_answer_a_line_alike(answers):
    assert answers["servo_sim"][:-1] == answers["vboard"][:-1]
    said = dict(zip(LINES, answers["servo_sim"]))
    assert said["supply 30001"] == "error: supply takes 0 to 30000 mV, not 30001"
    assert said["load -50.5"] == "error: load takes -50 to 50 N m, not -50.5"
    assert said["hostbaud 1100"] == "error: hostbaud takes 1200 to 4e+06 baud, not 1100"
    assert said["stop off"] == "ok" and said["supply off"] == "error: only stop takes off"
    assert said["supply x"] == "error: the value must be a number"
    assert said["supply"] == "error: missing value"
    assert said["nosuch"] == said["nosuch 3"] == "error: unknown command (try help)"


def test_unplug_takes_a_servo_off_the_bus_and_back():
    """servo_sim's unplug: the servo neither hears nor answers, the others
    still do; plugged back in, it answers again."""
    from servoctl.servo import Servo

    with Simulator(ids=[1, 2], fast=True) as sim, sim.bus(run_ahead=sim.bus_run_ahead) as bus:
        assert sim.control("unplug 1 1").strip() == "ok"
        assert not Servo(bus, 1).ping(timeout=0.05) and Servo(bus, 2).ping()
        assert sim.control("unplug 0 1").strip() == "ok"
        assert Servo(bus, 1).ping()
