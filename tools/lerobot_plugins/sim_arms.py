"""Two simulated 7-servo arms for LeRobot's leader-follower walk-through
(docs/lerobot.md): a follower on socket://127.0.0.1:5100 and a leader on
socket://127.0.0.1:5200, each servo_sim with IDs 0-6 at 1 Mbaud, soft
start off. Writes their ports to build/sim-arms.env (FOLLOWER_PORT,
FOLLOWER_CONTROL, LEADER_PORT, LEADER_CONTROL: a shell's `source`; --env
puts it elsewhere), prints the lerobot-teleoperate command that drives
them and runs until Ctrl-C or SIGTERM, which stop both.

    .venv/bin/python tools/lerobot_plugins/sim_arms.py [--follower 5100] [--leader 5200]
        [--env FILE] [--state DIR]

--state DIR keeps the servos' flash (DIR/follower, DIR/leader), so what
a calibration stores on them is there at the next start. An env file or
a state folder that a running instance holds is left alone: this one
stops, saying so (a second instance takes its own --env, --state and
ports; 0 is any free one). The running one holds a lock on each
(.FILE.lock beside the env file, DIR/.sim_arms.lock), which ends with
its process however it ends: an env file left by one killed is stale,
and the next start takes it. The simulators end with this process, by
kill -9 too (Linux's parent-death signal); SIGHUP, SIGTERM and Ctrl-C
stop both and remove the env file.

While they run, a hand on an arm: a torque on one released joint for a
moment (the leader's, or the follower's while it calibrates), then both
arms' horn angles a second later:

    .venv/bin/python tools/lerobot_plugins/sim_arms.py --nudge JOINT_ID [--arm follower] [--torque -0.5]"""
import argparse
import ctypes
import fcntl
import os
import signal
import sys
from pathlib import Path

from servoctl import link_rate
from servoctl.errors import ServoError
from servoctl.servo import Servo
from servoctl.sim import Simulator, _fields, control_command

IDS = range(7)
ENV = Path(__file__).resolve().parents[2] / "build" / "sim-arms.env"
BAUD_1M = 8  # item 36's index for 1 000 000 baud
RANGE_DECIDEG = (-1200, 1200)  # each joint's, as a calibration stores it (items 52, 51; 48 is on)


def die_with(parent: int) -> None:
    """In a simulator's process before it runs: SIGTERM once parent ends,
    however it ends (prctl PR_SET_PDEATHSIG); gone already, it ends now."""
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM, 0, 0, 0)  # 1: PR_SET_PDEATHSIG
    if os.getppid() != parent:
        os._exit(1)


def arm(tcp_port: int, state_dir=None) -> Simulator:
    """An arm at 1 Mbaud, soft start off, calibrated as the walk-through
    takes it (RANGE_DECIDEG stored as the angle limits: a new servo's
    factory +-135 deg is no calibration, and connect() would ask for one);
    servos that kept that from an earlier run (--state) are left as they
    are."""
    sim = Simulator(ids=IDS, tcp_port=tcp_port, state_dir=state_dir)
    parent = os.getpid()
    sim.preexec = lambda: die_with(parent)
    sim.start()
    try:
        link_rate.open_rate(sim.url, 1000000, str(sim.control_port))  # the host's rate on the socket
        with sim.bus(timeout=0.02, baud=1000000) as bus:
            new = [i for i in IDS if not Servo(bus, i).ping()]
        if new:
            link_rate.open_rate(sim.url, 115200, str(sim.control_port))
            with sim.bus(timeout=0.2) as bus:
                for i in new:
                    Servo(bus, i).write("soft_start_on", 0)
                    Servo(bus, i).write("angle_min", RANGE_DECIDEG[0])
                    Servo(bus, i).write("angle_max", RANGE_DECIDEG[1])
                    Servo(bus, i).write("baud", BAUD_1M)  # answered at 115200, then it switches
            link_rate.open_rate(sim.url, 1000000, str(sim.control_port))
    except BaseException:
        sim.stop()
        raise
    return sim


def read_env(path: Path) -> dict:
    return dict(line.split("=", 1) for line in path.read_text().split() if "=" in line)


def lock_of(path: Path) -> Path:
    """The lock a running instance holds for its env file (beside it)."""
    return path.with_name(f".{path.name}.lock")


def hold(lock: Path):
    """The lock's file, held by this process until it ends, or None where
    another process holds it."""
    lock.parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        return None
    return fd


def owner_pid(path: Path) -> str:
    try:
        return read_env(path).get("SIM_ARMS_PID", "?")
    except OSError:
        return "?"


def write_env(path: Path, text: str) -> None:
    """Whole or not at all: a shell waiting for the file sources it whole."""
    path.parent.mkdir(parents=True, exist_ok=True)
    new = path.with_name(f".{path.name}.{os.getpid()}")
    new.unlink(missing_ok=True)
    fd = os.open(new, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644)
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(new, path)


def nudge(env: Path, servo_id: int, arm_name: str = "leader", torque_nm: float = 0.5, seconds: float = 0.2) -> None:
    """One arm's joint pushed (its control port's load), then let be; for
    seconds of the simulator's clock, which a loaded PC does not stretch."""
    free = hold(lock_of(env))
    if free is not None:  # no instance holds it: none runs
        os.close(free)
        raise ServoError(f"no sim_arms.py runs with {env}" + (" (a stale file: the one that wrote it was stopped "
                         "without removing it)" if env.exists() else "") + ": start one first")
    ports = read_env(env)
    try:
        leader, follower = int(ports["LEADER_CONTROL"]), int(ports["FOLLOWER_CONTROL"])
    except (KeyError, ValueError):
        raise ServoError(f"{env} has no LEADER_CONTROL and FOLLOWER_CONTROL ports: not sim_arms.py's") from None
    pushed = leader if arm_name == "leader" else follower
    clock = Simulator.running(pushed)
    try:
        control_command(pushed, f"load {torque_nm} {servo_id}")
        clock.sleep(seconds)
        control_command(pushed, f"load 0 {servo_id}")
        clock.sleep(1.0)
    finally:
        clock.stop()  # its connection, not the simulator
    for name, port in (("leader", leader), ("follower", follower)):
        angles = [_fields(line)["angle"] for line in control_command(port, "state").splitlines() if line.strip()]
        print(f"{name:8} horns (deg): {' '.join(f'{a:7.1f}' for a in angles)}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--follower", type=int, default=5100, help="the follower's TCP port (0: any free one)")
    ap.add_argument("--leader", type=int, default=5200, help="the leader's TCP port (0: any free one)")
    ap.add_argument("--env", type=Path, default=ENV, help=f"the file of their ports (default {ENV})")
    ap.add_argument("--state", type=Path, metavar="DIR",
                    help="keep the servos' flash in DIR/follower and DIR/leader (default: a new one each run)")
    ap.add_argument("--nudge", type=int, metavar="JOINT_ID", help="push a running arm's joint, then show both")
    ap.add_argument("--arm", choices=("leader", "follower"), default="leader", help="the arm --nudge pushes")
    ap.add_argument("--torque", type=float, default=0.5, help="--nudge's torque, N m (negative: the other way)")
    args = ap.parse_args(argv)
    try:
        if args.nudge is not None:
            nudge(args.env, args.nudge, args.arm, args.torque)
            return 0
        return run(args)
    except (ServoError, OSError) as e:
        hint = (": another program has that port; give --follower and --leader free ones (0: any)"
                if "in use" in str(e) else "")
        print(f"sim_arms: {e}{hint}", file=sys.stderr)
        return 1


def stop_on(signum, frame) -> None:
    raise SystemExit(0)


def run(args) -> int:
    """Both arms until a signal; the env file removed on the way out."""
    locks = [hold(lock_of(args.env))]
    if locks[0] is None:
        print(f"sim_arms: another sim_arms.py (pid {owner_pid(args.env)}) runs with {args.env}: stop it, or give "
              f"this one its own --env FILE and ports", file=sys.stderr)
        return 1
    if args.state is not None:
        locks.append(hold(args.state / ".sim_arms.lock"))
        if locks[1] is None:
            print(f"sim_arms: another sim_arms.py runs with --state {args.state}: two would write the same "
                  f"servos' flash; stop it, or give this one its own --state DIR", file=sys.stderr)
            return 1
    sims, text = [], None
    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, stop_on)
    try:
        states = [None, None] if args.state is None else [args.state / "follower", args.state / "leader"]
        for d in filter(None, states):
            d.mkdir(parents=True, exist_ok=True)
        follower = arm(args.follower, states[0] and str(states[0]))
        sims.append(follower)
        leader = arm(args.leader, states[1] and str(states[1]))
        sims.append(leader)
        text = (f"FOLLOWER_PORT={follower.url}\nFOLLOWER_CONTROL={follower.control_port}\n"
                f"LEADER_PORT={leader.url}\nLEADER_CONTROL={leader.control_port}\nSIM_ARMS_PID={os.getpid()}\n")
        write_env(args.env, text)
        print(f"follower: {follower.url} (control {follower.control_port}); "
              f"leader: {leader.url} (control {leader.control_port}); in {args.env}")
        print(f"teleoperate:\n  bash scripts/lerobot_run.sh -m lerobot.scripts.lerobot_teleoperate "
              f"--robot.type=servoctl_arm --robot.port={follower.url} --robot.sim_control={follower.control_port} "
              f"--robot.id=sim_follower --teleop.type=servoctl_leader --teleop.port={leader.url} "
              f"--teleop.sim_control={leader.control_port} --teleop.id=sim_leader --fps=30")
        print("Ctrl-C stops both arms", flush=True)
        signal.pause()
    except KeyboardInterrupt:
        pass
    finally:
        for sig in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT):
            signal.signal(sig, signal.SIG_IGN)  # a second signal does not cut the cleanup short
        for sim in sims:
            sim.stop()
        try:
            if text is not None and args.env.read_text() == text:  # ours still: another's is left alone
                args.env.unlink()
        except FileNotFoundError:
            pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
