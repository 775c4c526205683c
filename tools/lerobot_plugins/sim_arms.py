"""Two simulated 7-servo arms for LeRobot's leader-follower walk-through
(docs/lerobot.md): a follower on socket://127.0.0.1:5100 and a leader on
socket://127.0.0.1:5200, each servo_sim with IDs 0-6 at 1 Mbaud, soft
start off. Writes their ports to build/sim-arms.env (FOLLOWER_PORT,
FOLLOWER_CONTROL, LEADER_PORT, LEADER_CONTROL: a shell's `source`), prints
the lerobot-teleoperate command that drives them and runs until Ctrl-C or
SIGTERM, which stop both.

    .venv/bin/python tools/lerobot_plugins/sim_arms.py [--follower 5100] [--leader 5200]

and, while they run, a hand on the leader: a torque on one released joint
for a moment, then both arms' horn angles once the follower has followed:

    .venv/bin/python tools/lerobot_plugins/sim_arms.py --nudge JOINT_ID"""
import argparse
import signal
import sys
import time
from pathlib import Path

from servoctl import link_rate
from servoctl.servo import Servo
from servoctl.sim import Simulator, _fields, control_command

IDS = range(7)
ENV = Path(__file__).resolve().parents[2] / "build" / "sim-arms.env"
BAUD_1M = 8  # item 36's index for 1 000 000 baud


def arm(tcp_port: int) -> Simulator:
    sim = Simulator(ids=IDS, tcp_port=tcp_port).start()
    with sim.bus(timeout=0.2) as bus:
        for i in IDS:
            Servo(bus, i).write("soft_start_on", 0)
            Servo(bus, i).write("baud", BAUD_1M)  # answered at 115200, then it switches
    link_rate.open_rate(sim.url, 1000000, str(sim.control_port))  # the host's rate on the socket
    return sim


def nudge(servo_id: int, torque_nm: float = 0.5, seconds: float = 0.2) -> None:
    """The leader's joint pushed (its control port's load), then let be."""
    env = dict(line.split("=", 1) for line in ENV.read_text().split())
    leader, follower = int(env["LEADER_CONTROL"]), int(env["FOLLOWER_CONTROL"])
    control_command(leader, f"load {torque_nm} {servo_id}")
    time.sleep(seconds)
    control_command(leader, f"load 0 {servo_id}")
    time.sleep(1.0)
    for name, port in (("leader", leader), ("follower", follower)):
        angles = [_fields(line)["angle"] for line in control_command(port, "state").splitlines() if line.strip()]
        print(f"{name:8} horns (deg): {' '.join(f'{a:7.1f}' for a in angles)}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--follower", type=int, default=5100, help="the follower's TCP port")
    ap.add_argument("--leader", type=int, default=5200, help="the leader's TCP port")
    ap.add_argument("--nudge", type=int, metavar="JOINT_ID", help="push the running leader's joint, then show both")
    args = ap.parse_args(argv)
    if args.nudge is not None:
        nudge(args.nudge)
        return 0
    sims = []
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    try:
        follower = arm(args.follower)
        sims.append(follower)
        leader = arm(args.leader)
        sims.append(leader)
        ENV.parent.mkdir(exist_ok=True)
        ENV.write_text(f"FOLLOWER_PORT={follower.url}\nFOLLOWER_CONTROL={follower.control_port}\n"
                       f"LEADER_PORT={leader.url}\nLEADER_CONTROL={leader.control_port}\n")
        print(f"follower: {follower.url} (control {follower.control_port}); "
              f"leader: {leader.url} (control {leader.control_port}); in {ENV}")
        print(f"teleoperate:\n  bash scripts/lerobot_run.sh -m lerobot.scripts.lerobot_teleoperate "
              f"--robot.type=servoctl_arm --robot.port={follower.url} --robot.sim_control={follower.control_port} "
              f"--robot.id=sim_follower --teleop.type=servoctl_leader --teleop.port={leader.url} "
              f"--teleop.sim_control={leader.control_port} --teleop.id=sim_leader --fps=30")
        print("Ctrl-C stops both arms", flush=True)
        signal.pause()
    except KeyboardInterrupt:
        pass
    finally:
        for sim in sims:
            sim.stop()
        ENV.unlink(missing_ok=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
