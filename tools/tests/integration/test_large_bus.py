"""254 simulated servos on one bus (IDs 0..253, the protocol's whole
range): a scan finds every one, and a Sync Monitor of all of them answers
in list order with no collision. The simulator used to refuse more than 16."""
from servoctl import protocol as p
from servoctl.cli import main
from servoctl.protocol import Bus
from servoctl.sim import Simulator

IDS = list(range(254))


def test_a_full_bus_scans_and_sync_monitors_without_collisions(tmp_path, capsys):
    with Simulator(fast=True, ids=IDS, state_dir=str(tmp_path / "state")) as sim:
        # The ASan build runs 254 servos at about real time; a scan allows
        # 20 ms an ID.
        rc = main(["--port", sim.url, "scan", "--reply-timeout", "0.02", "--json"], clock=sim.clock_s)
        out = capsys.readouterr().out
        assert rc == 0
        found = [entry["id"] for entry in __import__("json").loads(out)]
        assert found == IDS
        with sim.bus(timeout=2.0) as bus:
            order = list(reversed(IDS))
            bus.send(p.SYNC, bytes([p.MONITOR, 1, len(order)] + order))
            data = b""

            def all_answered():
                nonlocal data
                data += bus.serial.read(8192)
                return len(data) >= 21 * len(order)

            sim.wait_until(all_answered, 5.0)
        answered = [data[i + 4] for i in range(0, len(data), 21)]
        assert answered == order
        assert sim.state(0)["collisions"] == 0
