"""servoctl_leader's settings (docs/lerobot.md)."""
from dataclasses import dataclass

from lerobot.teleoperators.config import TeleoperatorConfig
from lerobot_robot_servoctl.joints import ArmBusConfig


@TeleoperatorConfig.register_subclass("servoctl_leader")
@dataclass
class ServoctlLeaderConfig(TeleoperatorConfig, ArmBusConfig):
    # 0: the arm released for a person to move it; else damped (MoveOnDampingMode) at this
    # power, mW: a little resistance that keeps a let-go arm from falling.
    damping_mw: int = 0
    # The gripper joint and the follower gripper's range, degrees (lowest, highest): the
    # leader's gripper range maps onto it, end to end. None: the leader's degrees as read.
    gripper: str = "gripper"
    follower_gripper_range: tuple[float, float] | None = None
