"""servoctl_leader: a leader arm of UART bus servos that a person moves.

connect() releases every joint (or damps it lightly, damping_mw) and
get_action() reads them all in one Sync Monitor: some 2 ms for 7 servos at
1 Mbaud, so LeRobot's loop is never waiting on it (>= 100 Hz). A servo
that does not answer raises JointNotAnsweringError naming the joint. The
gripper's range (the leader's limits, or its calibration) maps onto the
follower's (follower_gripper_range)."""
import logging

from lerobot.teleoperators import Teleoperator
from lerobot.utils.errors import DeviceAlreadyConnectedError, DeviceNotConnectedError
from lerobot_robot_servoctl import joints as j
from servoctl.arm import Arm
from servoctl.servo import Servo

from .config_servoctl_leader import ServoctlLeaderConfig

log = logging.getLogger(__name__)


class ServoctlLeader(j.OnArm, Teleoperator):
    config_class = ServoctlLeaderConfig
    name = "servoctl_leader"

    @property
    def action_features(self) -> dict:
        return {f"{n}.pos": float for n in self.config.joints}

    @property
    def feedback_features(self) -> dict:
        return {}

    @property
    def is_connected(self) -> bool:
        return self.arm is not None

    def connect(self, calibrate: bool = True) -> None:
        if self.arm is not None:
            raise DeviceAlreadyConnectedError(f"{self} already connected")
        bus = j.open_bus(self.config, self.clock)
        # The leader is moved by hand: no watchdog (its output is not driven).
        arm = Arm(bus, self.config.joints, firmware=self.config.firmware, watchdog_ms=0)
        try:
            with j.answering(self):
                arm.open()
            self.arm = arm
            self._let_go()
            if not self.is_calibrated and calibrate:
                self.calibrate()
        except BaseException:
            self.arm = None
            bus.close()
            raise
        log.info("%s connected (%s firmware), %s", self, arm.firmware,
                 f"damped at {self.config.damping_mw} mW" if self.config.damping_mw else "released")

    def _let_go(self) -> None:
        for servo_id in self.arm.ids:
            if self.config.damping_mw:
                Servo(self.arm.bus, servo_id).damping(self.config.damping_mw)
            else:
                Servo(self.arm.bus, servo_id).stop("release")

    def calibrate(self) -> None:
        super().calibrate()
        self._let_go()

    def configure(self) -> None:
        pass

    def gripper_range(self) -> tuple:
        """The leader gripper's range, degrees: its servo's limits on this
        firmware, its calibration on the maker's; None if neither."""
        name = self.config.gripper
        if self.arm.firmware == "servoctl":
            lim = self.arm.limits[self.config.joints[name]]
            return None if lim.angle_min is None else (lim.angle_min / 10.0, lim.angle_max / 10.0)
        c = self.calibration.get(name)
        return None if c is None else ((c.range_min - c.homing_offset) / 10.0, (c.range_max - c.homing_offset) / 10.0)

    def get_action(self) -> dict:
        if not self.is_connected:
            raise DeviceNotConnectedError(f"{self} is not connected.")
        with j.answering(self):
            pos = self._calibrated().observed(self.arm.positions())
        name, follower = self.config.gripper, self.config.follower_gripper_range
        mine = self.gripper_range() if follower is not None and name in pos else None
        if mine is not None and mine[1] > mine[0]:
            share = min(max((pos[name] - mine[0]) / (mine[1] - mine[0]), 0.0), 1.0)
            pos[name] = round(follower[0] + share * (follower[1] - follower[0]), 1)
        return {f"{n}.pos": d for n, d in pos.items()}

    def send_feedback(self, feedback: dict) -> None:
        pass  # a leader of bus servos has no haptics to drive

    def disconnect(self) -> None:
        if not self.is_connected:
            raise DeviceNotConnectedError(f"{self} is not connected.")
        arm, self.arm = self.arm, None
        try:
            for servo_id in arm.ids:
                Servo(arm.bus, servo_id).stop("release")
        finally:
            arm.bus.close()
        log.info("%s disconnected", self)
