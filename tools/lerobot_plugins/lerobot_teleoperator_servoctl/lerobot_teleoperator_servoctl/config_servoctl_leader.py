"""servoctl_leader's settings (docs/lerobot.md)."""
from dataclasses import dataclass, field

from lerobot.teleoperators.config import TeleoperatorConfig
from lerobot_robot_servoctl.joints import default_joints


@TeleoperatorConfig.register_subclass("servoctl_leader")
@dataclass
class ServoctlLeaderConfig(TeleoperatorConfig):
    port: str
    baud: int = 1_000_000
    # Joint name -> servo ID: the follower's names, so its actions fit the follower.
    joints: dict[str, int] = field(default_factory=default_joints)
    # 0: the arm released for a person to move it; else damped (MoveOnDampingMode) at this
    # power, mW: a little resistance that keeps a let-go arm from falling.
    damping_mw: int = 0
    # The gripper joint and the follower gripper's range, degrees (lowest, highest): the
    # leader's gripper range maps onto it, end to end. None: the leader's degrees as read.
    gripper: str = "gripper"
    follower_gripper_range: tuple[float, float] | None = None
    firmware: str = "auto"
    sim_control: str | None = None
