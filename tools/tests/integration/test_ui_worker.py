"""servoctl ui's bus thread (ui/worker.py) without a browser: what the
page's requests do on servo_sim, judged on the simulator's state."""
from servoctl.sim import Simulator
from servoctl.ui.worker import Worker


def _worker(sim, said):
    argv = ["--port", sim.url, "--sim-control", str(sim.control_port)]
    return Worker(sim.bus(), argv, said.append)


def test_stop_all_stops_a_servo_the_last_scan_did_not_list():
    """Servos left out of the last scan (none yet, a shared ID, a new ID
    given since) are stopped too: stop-all is the user's emergency stop."""
    with Simulator(ids=[1, 2], fast=True) as sim:
        said = []
        w = _worker(sim, said)
        assert w.run(["wheel", "2", "run", "--speed", "180"])["code"] == 0
        sim.wait_until(lambda: abs(sim.state(2)["velocity"]) > 100, timeout_s=10)
        w.known = [1]  # a scan that missed servo 2
        w.stop_all("damping")
        sim.wait_until(lambda: abs(sim.state(2)["velocity"]) < 2, timeout_s=5)
        assert said[-1]["type"] == "stopped" and not said[-1]["failed"], said[-1]
