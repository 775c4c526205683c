"""What the follower (servoctl_arm) and the leader (servoctl_leader) share:
the bus, the joints' default layout, the errors LeRobot is given and the
calibration, on servoctl's Arm (servoctl/arm.py; docs/lerobot.md)."""
import contextlib
import logging
import os
from dataclasses import dataclass, field

from lerobot.motors import MotorCalibration
from lerobot.utils.errors import DeviceNotConnectedError
from lerobot.utils.utils import enter_pressed
from servoctl import link_rate
from servoctl.arm import Arm, JointShared, JointSilent
from servoctl.protocol import Bus
from servoctl.servo import Servo

log = logging.getLogger(__name__)

# The maker's 7-servo arms (Viola, Cello; Violin the leader): IDs 0-6, the
# last the gripper; the names its LeRobot plugin gives them.
DEFAULT_JOINTS = {**{f"Motor_{k}": k for k in range(6)}, "gripper": 6}


def default_joints() -> dict:
    return dict(DEFAULT_JOINTS)


@dataclass
class ArmBusConfig:
    """The settings of servoctl_arm's and servoctl_leader's bus and joints
    (each plugin's config adds its own; docs/lerobot.md)."""
    # A serial port (/dev/ttyUSB0) or a pyserial URL (socket://127.0.0.1:5000, a simulator).
    port: str
    baud: int = 1_000_000
    # Joint name -> servo ID; the maker's 7-joint layout, the last the gripper. A leader's
    # are the follower's names, so its actions fit the follower.
    joints: dict[str, int] = field(default_factory=default_joints)
    # "auto" (asks the servos), "servoctl" (this firmware) or "maker" (the maker's packets only).
    firmware: str = "auto"
    # A simulator's control port (servoctl sim prints it): the baud rate of a socket://
    # link is set there and the bus waits on the simulated clock.
    sim_control: str | None = None


class JointNotAnsweringError(DeviceNotConnectedError):
    """A joint's servo did not answer in its slot: no stale value is given.
    joints: the names of those that did not."""

    def __init__(self, message: str, joints=()):
        super().__init__(message)
        self.joints = list(joints)


def host_timing(device) -> str:
    """What else a silence may be on a simulator's link (socket://, or its
    pseudo-terminal) without sim_control (or a clock given): the bus waits
    on this computer's clock, and a simulator behind real time (a slow or
    loaded host) answers after it gave up. A real servo's answer waits in
    the adapter for a late read."""
    config = device.config
    simulated = link_rate.is_socket(config.port) or os.path.realpath(config.port or "").startswith("/dev/pts/")
    if not simulated or config.sim_control or device.clock is not None:
        return ""
    return ("; or, on a simulator's link without sim_control, the host's timing: the bus waits on this "
            "computer's clock, and a simulator that falls behind real time (a slow or loaded host) answers "
            "after the bus has given up; give its control port as sim_control, and the bus waits on the "
            "simulated clock")


@contextlib.contextmanager
def answering(device):
    """JointSilent as LeRobot's DeviceNotConnectedError, naming the joint
    (and, on a simulator's link without sim_control, the host's timing)."""
    try:
        yield
    except JointShared as e:
        raise JointNotAnsweringError(f"{device}: {e}", e.joints) from None
    except JointSilent as e:
        raise JointNotAnsweringError(f"{device}: {e}{host_timing(device)}", e.joints) from None


def open_bus(config, clock=None) -> Bus:
    """The bus at config.baud. On a simulator's socket:// link the rate is
    set through its control port (config.sim_control), and the bus waits on
    the simulated clock (clock, or the simulator's); a socket without it
    carries no rate, and the host's clock is used. The simulator's clock
    (a control connection kept open) is closed with the bus."""
    sim = link_rate.simulator(config.sim_control)
    if sim is not None and link_rate.is_socket(config.port):
        link_rate.open_rate(config.port, config.baud, config.sim_control)
    bus = Bus(config.port, config.baud, timeout=0.05, clock=clock or (sim and sim.clock_s))
    if sim is not None:
        close = bus.close

        def close_both():
            try:
                close()
            finally:
                sim.stop()  # Simulator.running: its connection, not the simulator
        bus.close = close_both
    return bus


def record_ranges(arm: Arm, stop) -> dict:
    """{name: (lowest, highest) deg} seen while a person moves each joint
    through its range, until stop() (ENTER) says it is done."""
    seen = {}
    while True:
        for name, deg in arm.positions().items():
            lo, hi = seen.get(name, (deg, deg))
            seen[name] = (min(lo, deg), max(hi, deg))
        if stop():
            return seen


def calibrate(device, arm: Arm, prompt, stop) -> dict:
    """LeRobot's two steps, the arm released: the middle of each joint's
    range, then its range. On this firmware both are stored on the servos
    (the zero in item 90, the range as the angle limits 51, 52), so the
    file LeRobot keeps holds offsets of 0; on the maker's they are in the
    file only (homing_offset and the range, 0.1 deg), applied by the
    plugin. Returns {name: MotorCalibration}."""
    for servo_id in arm.ids:
        Servo(arm.bus, servo_id).stop("release")
    prompt(f"{device}: move the arm to the middle of its range of motion, then press ENTER...")
    if arm.firmware == "servoctl":
        arm.set_zero_here()
        offsets = dict.fromkeys(arm.joints, 0)
    else:
        offsets = {n: round(d * 10) for n, d in arm.positions().items()}  # the servo's own angle, 0.1 deg
    print(f"{device}: move every joint through its whole range of motion; press ENTER to stop...")
    ranges = record_ranges(arm, stop)
    if arm.firmware == "servoctl":
        arm.store_ranges(ranges)
    return {name: MotorCalibration(id=arm.joints[name], drive_mode=0, homing_offset=offsets[name],
                                   range_min=round(lo * 10), range_max=round(hi * 10))
            for name, (lo, hi) in ranges.items()}



class Calibrated:
    """A LeRobot calibration applied on the host: angles from each joint's
    homing_offset, targets within range_min..range_max (0.1 deg, the
    servo's own angle). On this firmware the offsets are 0 and the range
    the servo's own limits."""

    def __init__(self, calibration: dict):
        self.cal = calibration

    def observed(self, raw: dict) -> dict:
        return {n: round(d - self._off(n), 1) for n, d in raw.items()}

    def target(self, wanted: dict) -> dict:
        out = {}
        for name, deg in wanted.items():
            raw = deg + self._off(name)
            c = self.cal.get(name)
            if c is not None:
                raw = min(max(raw, c.range_min / 10.0), c.range_max / 10.0)
            out[name] = raw
        return out

    def _off(self, name: str) -> float:
        c = self.cal.get(name)
        return c.homing_offset / 10.0 if c is not None else 0.0


class OnArm:
    """What servoctl_arm and servoctl_leader do alike: their state, their
    calibration, and the host's share of it (Calibrated)."""

    def __init__(self, config):
        super().__init__(config)  # LeRobot's Robot or Teleoperator
        self.config = config
        self.arm = None
        # The bus's clock: None is the simulator's (sim_control) or the host's.
        self.clock = None
        # calibrate()'s questions and its ENTER: replaceable (a script, a test).
        self.prompt, self.stop_recording = input, enter_pressed

    @property
    def is_calibrated(self) -> bool:
        if self.arm is not None and self.arm.firmware == "servoctl":
            return self.arm.ranges_stored()
        return bool(self.calibration)

    def calibrate(self) -> None:
        with answering(self):
            self.calibration = calibrate(self, self.arm, self.prompt, self.stop_recording)
        self._save_calibration()
        print(f"{self}: calibration saved to {self.calibration_fpath}")

    def _calibrated(self) -> Calibrated:
        # This firmware keeps its own zero and limits: the file is the servos' record.
        return Calibrated({} if self.arm.firmware == "servoctl" else self.calibration)
