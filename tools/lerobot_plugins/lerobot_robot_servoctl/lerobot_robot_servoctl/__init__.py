"""LeRobot's follower robot servoctl_arm (docs/lerobot.md)."""
from .config_servoctl_arm import ServoctlArmConfig
from .servoctl_arm import ServoctlArm

__all__ = ["ServoctlArm", "ServoctlArmConfig"]
