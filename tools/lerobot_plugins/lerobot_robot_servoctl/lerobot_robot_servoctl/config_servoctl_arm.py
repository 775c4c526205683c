"""servoctl_arm's settings (docs/lerobot.md)."""
from dataclasses import dataclass, field

from lerobot.cameras import CameraConfig
from lerobot.robots.config import RobotConfig

from .joints import default_joints


@RobotConfig.register_subclass("servoctl_arm")
@dataclass
class ServoctlArmConfig(RobotConfig):
    # A serial port (/dev/ttyUSB0) or a pyserial URL (socket://127.0.0.1:5000, a simulator).
    port: str
    baud: int = 1_000_000
    # Joint name -> servo ID; the maker's 7-joint layout, the last the gripper.
    joints: dict[str, int] = field(default_factory=default_joints)
    # The most a target may be from where the joint is, degrees (one number, or one a joint).
    max_relative_target: float | dict[str, float] | None = None
    # This firmware's bus watchdog while connected (items 64, 65): a host silent this long
    # leaves the arm holding ("hold"), damped ("damp") or free ("release"). 0: left as it is.
    watchdog_ms: int = 500
    watchdog_action: str = "hold"
    disable_torque_on_disconnect: bool = True
    # The loop's frames a second (lerobot-teleoperate --fps, lerobot-record --dataset.fps):
    # the streamed setpoints' period.
    fps: float = 30.0
    # "auto" (asks the servos), "servoctl" (this firmware) or "maker" (the maker's packets only).
    firmware: str = "auto"
    # A simulator's control port (servoctl sim prints it): the baud rate of a socket://
    # link is set there and the bus waits on the simulated clock.
    sim_control: str | None = None
    cameras: dict[str, CameraConfig] = field(default_factory=dict)
