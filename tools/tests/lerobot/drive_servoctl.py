"""Run in the LeRobot environment by test_servoctl_plugins.py (through
scripts/lerobot_run.sh, which pip-installs the checkout's plugins), not by
pytest: servoctl_arm and servoctl_leader, found by LeRobot's own
third-party discovery and made by make_robot_from_config /
make_teleoperator_from_config, on simulated 7-servo arms (IDs 0-6, 1
Mbaud, servo_sim paced: its clock moves only while the host waits on it,
so what it sees does not depend on the host's speed). Prints one JSON line
of what it saw."""
import json
import shutil
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lerobot_plugins"))

import compare  # noqa: E402 - tools/lerobot_plugins/compare.py, the comparison's own run
from lerobot.robots.config import RobotConfig  # noqa: E402
from lerobot.robots.utils import make_robot_from_config  # noqa: E402
from lerobot.teleoperators.config import TeleoperatorConfig  # noqa: E402
from lerobot.teleoperators.utils import make_teleoperator_from_config  # noqa: E402
from lerobot.utils.import_utils import register_third_party_plugins  # noqa: E402
from servoctl.protocol import Bus  # noqa: E402
from servoctl.servo import Servo  # noqa: E402
from servoctl.sim import Simulator  # noqa: E402

IDS = compare.IDS


CAL = Path(tempfile.mkdtemp(prefix="lerobot-cal-"))  # the calibration files; removed at the end


def follower(sim, **kw):
    cfg = RobotConfig.get_choice_class("servoctl_arm")(port=sim.url, id="test", calibration_dir=Path(
        tempfile.mkdtemp(dir=CAL)), **kw)
    robot = make_robot_from_config(cfg)
    robot.clock = sim.clock_s
    return robot


def frames(robot, sim, targets: dict, n: int) -> None:
    t0 = sim.clock_s()
    for k in range(n):
        robot.get_observation()
        robot.send_action({f"{name}.pos": d for name, d in targets.items()})
        robot.arm.bus.sleep(t0 + (k + 1) / 30 - sim.clock_s())


def refused_settings(out: dict) -> None:
    """Settings that would drive the arm wrong, refused as the config is
    made: {setting: the error's text}."""
    cls = RobotConfig.get_choice_class("servoctl_arm")
    out["refused"] = {}
    for name, value in [("max_relative_target", -5.0), ("max_relative_target", float("nan")),
                        ("max_relative_target", {"Motor_0": 5.0, "Motor_1": -1.0}),
                        ("max_relative_target", {"nosuch": 5.0}), ("fps", 0), ("fps", -30.0), ("fps", 10000),
                        ("watchdog_ms", -1), ("watchdog_action", "explode"), ("ramp_speed_deg_s", -1.0),
                        ("baud", 0), ("baud", True), ("baud", 10**12), ("joints", ["a"]),
                        ("max_relative_target", {1: 5.0}), ("joints", {"a": 1, "b": 1}), ("joints", {"a": 300}),
                        ("firmware", "bogus"), ("watchdog_ms", 40)]:
        try:
            cls(port="socket://127.0.0.1:1", **{name: value})
            out["refused"][f"{name}={value}"] = None
        except ValueError as e:
            out["refused"][f"{name}={value}"] = str(e)


def follower_session(out: dict) -> None:
    sim = compare.prepare(paced=True)
    try:
        # A connect() that Arm refuses (two joints, one servo) leaves the port
        # closed: the next connect() found it "in use by another program".
        shared = follower(sim)  # its config checked, then changed as a program might
        shared.config.joints = {**{f"Motor_{i}": i for i in IDS}, "Motor_extra": 0}
        try:
            shared.connect(calibrate=False)
            out["shared_connect"] = None
        except Exception as e:  # noqa: BLE001 - what the user sees, said whatever it is
            out["shared_connect"] = str(e)
            kept = e  # noqa: F841 - its traceback keeps connect()'s frames, as a REPL's last error does
        # max_relative_target alone: no ramp after connect (ramped() has it); a
        # cap for one joint (the others uncapped: a KeyError before)
        robot = follower(sim, max_relative_target={"Motor_0": 5.0}, ramp_speed_deg_s=0)
        out["robot_class"] = type(robot).__name__
        robot.connect(calibrate=False)
        bus = robot.arm.bus
        out["firmware"] = robot.arm.firmware
        out["watchdog_connected"] = [(Servo(bus, i).read("watchdog_ms"), Servo(bus, i).read("watchdog_action"))
                                     for i in IDS]
        obs = robot.get_observation()
        out["first_obs"] = obs
        # max_relative_target: 40 deg asked, 5 deg given (from where the joint is).
        sent = robot.send_action({"Motor_0.pos": obs["Motor_0.pos"] + 40.0, "Motor_1.pos": obs["Motor_1.pos"] + 2.0})
        out["clamped"] = sent["Motor_0.pos"] - obs["Motor_0.pos"]
        out["uncapped"] = sent["Motor_1.pos"] - obs["Motor_1.pos"]
        out["bad_actions"] = []
        for bad in ({"Motor_0.pos": float("inf")}, {"Motor_0.pos": None}):
            try:
                robot.send_action(bad)
                out["bad_actions"].append(None)
            except ValueError as e:
                out["bad_actions"].append(str(e))
        # A policy that stops: the watchdog (500 ms, hold) takes over and logs it.
        sim.sleep(0.8)
        out["faults_after_silence"] = [f.kind for f in Servo(bus, 0).faults()[:1]]
        # A servo that lets its output go (its supply above item 40): an error with its faults.
        sim.control("supply 9500 2")
        sim.sleep(0.05)
        try:
            robot.get_observation()
            out["fault_error"] = None
        except Exception as e:  # noqa: BLE001 - the error is what is tested
            out["fault_error"] = f"{type(e).__name__}: {e}"
        sim.control("supply 7400 2")
        sim.sleep(0.1)
        robot.disconnect()
        with sim.bus(timeout=0.2, baud=1000000) as b:
            out["watchdog_after"] = [Servo(b, i).read("watchdog_ms") for i in IDS]
    finally:
        sim.stop()


def ramped(out: dict) -> None:
    """The default config: the first actions after connect, 40 deg from
    where the arm is, ramp there (the horn's top speed, on the models)."""
    sim = compare.prepare(paced=True)
    try:
        robot = follower(sim)
        robot.connect(calibrate=False)
        out["ramp_speed_deg_s"] = robot.arm.ramp.speed_deg_s
        goal = robot.get_observation()["Motor_1.pos"] + 40.0
        t0, peak = sim.clock_s(), 0.0
        for k in range(45):
            robot.send_action({"Motor_1.pos": goal})
            while sim.clock_s() < t0 + (k + 1) / 30:  # the next frame on time, however long a send took
                sim.sleep(max(min(0.005, t0 + (k + 1) / 30 - sim.clock_s()), 2e-6))
                peak = max(peak, abs(sim.state(1)["velocity"]))
        out["ramp_peak_dps"] = peak
        out["ramp_reached"] = robot.get_observation()["Motor_1.pos"] - goal
        robot.disconnect()
    finally:
        sim.stop()


def makers_path(out: dict) -> None:
    """firmware="maker": the maker's packets only, on this firmware (which
    carries them out as the maker's servo does): angle moves fitted to the
    frame period measured."""
    sim = compare.prepare(paced=True)
    try:
        robot = follower(sim, firmware="maker")
        robot.connect(calibrate=False)
        start = robot.get_observation()["Motor_2.pos"]
        t0 = sim.clock_s()
        for k in range(30):  # a ramp of 30 deg/s for a second
            robot.get_observation()
            robot.send_action({"Motor_2.pos": start + 30.0 * (k + 1) / 30})
            robot.arm.bus.sleep(t0 + (k + 1) / 30 - sim.clock_s())
        out["maker_period_ms"] = robot.arm.measured_period_s * 1000
        sim.sleep(0.2)
        out["maker_moved"] = robot.get_observation()["Motor_2.pos"] - start
        # Calibrated there (no joint moved through a range: ENTER at once): a LeRobot
        # file of offsets, the servos' own limits untouched.
        robot.prompt, robot.stop_recording = (lambda _: ""), (lambda: True)
        robot.calibrate()
        out["maker_cal"] = {n: c.homing_offset for n, c in robot.calibration.items()}
        out["maker_cal_obs"] = robot.get_observation()
        out["maker_limits"] = [Servo(robot.arm.bus, i).read("angle_max") for i in IDS]
        robot.disconnect()
    finally:
        sim.stop()


def calibration(out: dict) -> None:
    """calibrate(): the middle, then the ranges a person moves each joint
    through (here: moves sent while it records), stored on the servos."""
    sim = compare.prepare(paced=True)
    try:
        robot = follower(sim)
        robot.connect(calibrate=False)
        out["new_is_calibrated"] = robot.is_calibrated  # the factory's limits: not a calibration
        bus = robot.arm.bus
        swings = iter([30.0, -30.0])
        state = {"target": None, "calls": 0}

        def stop():  # between reads: swing every joint one way, then the other
            state["calls"] += 1
            if state["target"] is None or all(abs(d - state["target"]) < 0.3
                                              for d in robot.arm.positions().values()):
                state["target"] = next(swings, None)
                if state["target"] is None:
                    return True
                for i in IDS:
                    Servo(bus, i).move(round(state["target"] * 10), interval_ms=500)
            bus.sleep(0.02)
            return False
        robot.prompt, robot.stop_recording = (lambda _: ""), stop
        robot.calibrate()
        out["cal_limits"] = [(Servo(bus, i).read("angle_min"), Servo(bus, i).read("angle_max"),
                              Servo(bus, i).read("angle_limit_on")) for i in IDS]
        out["cal_zero"] = [Servo(bus, i).read("encoder_zero") for i in IDS]
        out["cal_file"] = robot.calibration_fpath.is_file()
        out["is_calibrated"] = robot.is_calibrated
        robot.disconnect()
    finally:
        sim.stop()


def leader(out: dict) -> None:
    sim = compare.prepare(paced=True)
    try:
        cfg = TeleoperatorConfig.get_choice_class("servoctl_leader")(
            port=sim.url, id="test", calibration_dir=Path(tempfile.mkdtemp(dir=CAL)),
            follower_gripper_range=(-10.0, 40.0))
        teleop = make_teleoperator_from_config(cfg)
        teleop.clock = sim.clock_s
        out["teleop_class"] = type(teleop).__name__
        teleop.connect(calibrate=False)
        out["leader_released"] = [bool(Servo(teleop.arm.bus, i).read_motion().flags & 16) for i in IDS]
        t0, n = sim.clock_s(), 100
        for _ in range(n):
            action = teleop.get_action()
        out["leader_hz"] = n / (sim.clock_s() - t0)
        out["leader_action"] = action
        out["leader_start"] = compare.START
        teleop.disconnect()
    finally:
        sim.stop()


def main() -> int:
    register_third_party_plugins()
    out = {}
    try:
        refused_settings(out)
        follower_session(out)
        ramped(out)
        makers_path(out)
        calibration(out)
        leader(out)
        clock_connection(out)
        past_the_wrap(out, reset_turns=False)
        past_the_wrap(out, reset_turns=True)
        host_timing(out)
        ours(out)
        out["peak_accel_none_kept"] = compare.peak_accel([], 0.0)  # every frame late: no figure
    finally:
        shutil.rmtree(CAL, ignore_errors=True)
    print(json.dumps(out))
    return 0


def ours(out: dict) -> None:
    """The comparison's run of ours, on a paced simulator: on time, and as
    a real host sends (+-10 ms, one frame in twenty a period late)."""
    out["compare"] = compare.run(compare.Ours())
    out["compare_jitter"] = compare.run(compare.Ours(), compare.HostTiming(0.010, 20))


def past_the_wrap(out: dict, reset_turns: bool) -> None:
    """Servo 5 with limits -36.9..175.2 resting at 188 deg (0 turns), its
    turns reset or not (-172.0 or 188.0): connect() takes it the short way
    to 175.2; the simulator's angle of its horn sampled at every wait."""
    sim = compare.prepare(paced=True)
    key = "wrap_reset" if reset_turns else "wrap"
    try:
        with sim.bus(timeout=0.2, baud=1000000) as b:
            s = Servo(b, 5)
            s.move(1880, interval_ms=500, multi_turn=True)
            sim.sleep(0.8)
            s.stop("release")
            for item, value in (("angle_min", -369), ("angle_max", 1752), ("angle_limit_on", 1)):
                s.write(item, value)
            if reset_turns:
                s.reset_multi_turn()
                sim.sleep(0.01)
            out[key + "_before"] = [s.multi_turn_angle()[0] / 10, sim.state(5)["angle"]]
        seen, sleep = [], Bus.sleep

        def sampled(bus, seconds):
            sleep(bus, seconds)
            seen.append(sim.state(5)["angle"])
        Bus.sleep = sampled
        robot = follower(sim)
        try:
            robot.connect(calibrate=False)
        finally:
            Bus.sleep = sleep
        out[key + "_held"] = robot.get_observation()["Motor_5.pos"]
        out[key + "_seen"] = [min(seen, default=None), max(seen, default=None), len(seen)]
        out[key + "_after"] = sim.state(5)["angle"]
        robot.disconnect()
    finally:
        sim.stop()


def host_timing(out: dict) -> None:
    """A paced simulator's link without sim_control, the bus on this
    computer's clock: nothing answers, and the error says the host's
    timing may be why, not only power and baud."""
    sim = compare.prepare(paced=True)
    try:
        cfg = RobotConfig.get_choice_class("servoctl_arm")(port=sim.url, id="timing", calibration_dir=Path(
            tempfile.mkdtemp(dir=CAL)), joints={"Motor_0": 0})
        robot = make_robot_from_config(cfg)
        try:
            robot.connect(calibrate=False)
            out["timing_error"] = None
            robot.disconnect()
        except Exception as e:  # noqa: BLE001 - the error is what is tested
            out["timing_error"] = f"{type(e).__name__}: {e}"
    finally:
        sim.stop()


def clock_connection(out: dict) -> None:
    """Given sim_control and no clock, the bus waits on the simulator's
    clock, asked on a control connection kept open: closed on disconnect
    (it was left open). A real-time simulator: the clock is only asked."""
    sim = Simulator(ids=[0], tcp=False).start()
    try:
        robot = make_robot_from_config(RobotConfig.get_choice_class("servoctl_arm")(
            port=sim.url, baud=115200, joints={"j": 0}, sim_control=str(sim.control_port), id="conn",
            calibration_dir=Path(tempfile.mkdtemp(dir=CAL))))
        robot.connect(calibrate=False)
        robot.get_observation()
        conn = robot.arm.bus.clock.__self__._clock_conn
        opened = conn is not None and conn.fileno() != -1
        robot.disconnect()
        out["clock_conn"] = [opened, conn is None or conn.fileno() == -1]
    finally:
        sim.stop()


if __name__ == "__main__":
    sys.exit(main())
