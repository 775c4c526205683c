"""servoctl_arm: a follower arm of UART bus servos, through servoctl's Arm.

- connect() never moves the arm: each joint is held where it is, and that
  is the first target; the first actions ramp from there at
  ramp_speed_deg_s. On this firmware the bus watchdog is armed while
  connected (watchdog_ms, watchdog_action).
- send_action() streams setpoints on this firmware (the servo joins the
  frames with a cubic); on the maker's it sends angle moves timed to the
  frame period measured between calls.
- get_observation() is fresh or raises JointNotAnsweringError (a
  DeviceNotConnectedError) naming the joint; a servo that let its output
  go raises with its fault history.
- calibrate(): the zero (item 90) and the ranges stored on the servos on
  this firmware; a LeRobot calibration file on the maker's."""
import logging
import math
from functools import cached_property

from lerobot.robots import Robot
from lerobot.robots.utils import ensure_safe_goal_position
from lerobot.utils.errors import DeviceAlreadyConnectedError, DeviceNotConnectedError
from servoctl.arm import Arm

from . import joints as j
from .config_servoctl_arm import ServoctlArmConfig

log = logging.getLogger(__name__)


class ServoctlArm(j.OnArm, Robot):
    config_class = ServoctlArmConfig
    name = "servoctl_arm"

    def __init__(self, config: ServoctlArmConfig):
        super().__init__(config)  # j.OnArm's, then Robot's
        from lerobot.cameras.utils import make_cameras_from_configs

        self.cameras = make_cameras_from_configs(config.cameras)

    @cached_property
    def observation_features(self) -> dict:
        return {**{f"{n}.pos": float for n in self.config.joints},
                **{k: (c.height, c.width, 3) for k, c in self.config.cameras.items()}}

    @cached_property
    def action_features(self) -> dict:
        return {f"{n}.pos": float for n in self.config.joints}

    @property
    def is_connected(self) -> bool:
        return self.arm is not None and all(c.is_connected for c in self.cameras.values())

    def connect(self, calibrate: bool = True) -> None:
        if self.arm is not None:
            raise DeviceAlreadyConnectedError(f"{self} already connected")
        bus = j.open_bus(self.config, self.clock)
        try:  # a refusal leaves no port open: the next connect() found it "in use"
            arm = Arm(bus, self.config.joints, self.config.fps, self.config.firmware,
                      self.config.watchdog_ms, self.config.watchdog_action, self.config.ramp_speed_deg_s)
        except BaseException:
            bus.close()
            raise
        try:
            with j.answering(self):
                arm.open()
            self.arm = arm
            if not self.is_calibrated and calibrate:
                self.calibrate()
            with j.answering(self):
                arm.hold_here()
        except BaseException:
            self.arm = None
            try:
                arm.close(release=False)  # the watchdog as it was, where the servos answer
            except Exception as e:  # noqa: BLE001 - the first error is the one to see
                log.warning("%s: %s", self, e)
            bus.close()
            raise
        for cam in self.cameras.values():
            cam.connect()
        log.info("%s connected (%s firmware), holding where it is", self, arm.firmware)

    def configure(self) -> None:
        pass

    def get_observation(self) -> dict:
        if not self.is_connected:
            raise DeviceNotConnectedError(f"{self} is not connected.")
        with j.answering(self):
            obs = self._calibrated().observed(self.arm.positions())
        out = {f"{n}.pos": d for n, d in obs.items()}
        for key, cam in self.cameras.items():
            out[key] = cam.async_read()
        return out

    def send_action(self, action: dict) -> dict:
        if not self.is_connected:
            raise DeviceNotConnectedError(f"{self} is not connected.")
        try:
            goal = {k.removesuffix(".pos"): float(v) for k, v in action.items() if k.endswith(".pos")}
        except (TypeError, ValueError):
            wrong = [k for k, v in action.items() if k.endswith(".pos") and not isinstance(v, (int, float))]
            raise ValueError(f"{self}: an action's angles are numbers, not {', '.join(wrong)}") from None
        cal = self._calibrated()
        if self.config.max_relative_target is not None:
            # A target that is no number is Arm.send's to refuse, not a cap's
            # to turn into present + cap (inf moved the joint a cap a frame).
            wrong = [n for n, g in goal.items() if not math.isfinite(g)]
            if wrong:
                raise ValueError(f"{self}: the action's {', '.join(wrong)} is not a finite angle")
            with j.answering(self):
                present = cal.observed(self.arm.positions())
            # A joint the dict leaves out has no cap; one the arm does not have
            # goes on to Arm.send, which names it.
            cap = self.config.max_relative_target
            known = {n: g for n, g in goal.items() if n in present}
            cap = {n: float(cap.get(n, math.inf)) for n in known} if isinstance(cap, dict) else float(cap)
            if known:
                goal = {**goal, **ensure_safe_goal_position({n: (g, present[n]) for n, g in known.items()}, cap)}
        with j.answering(self):
            sent = cal.observed(self.arm.send(cal.target(goal)))
        return {f"{n}.pos": sent[n] for n in goal}

    def disconnect(self) -> None:
        if not self.is_connected:
            raise DeviceNotConnectedError(f"{self} is not connected.")
        arm, self.arm = self.arm, None
        try:
            arm.close(release=self.config.disable_torque_on_disconnect)
        finally:
            arm.bus.close()
            for cam in self.cameras.values():
                cam.disconnect()
        log.info("%s disconnected", self)
