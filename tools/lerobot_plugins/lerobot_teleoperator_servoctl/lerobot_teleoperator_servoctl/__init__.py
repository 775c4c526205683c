"""LeRobot's leader teleoperator servoctl_leader (docs/lerobot.md)."""
from .config_servoctl_leader import ServoctlLeaderConfig
from .servoctl_leader import ServoctlLeader

__all__ = ["ServoctlLeader", "ServoctlLeaderConfig"]
