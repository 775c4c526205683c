"""servoctl_arm's settings (docs/lerobot.md)."""
import math
from dataclasses import dataclass, field

from lerobot.cameras import CameraConfig
from lerobot.robots.config import RobotConfig
from servoctl.arm_ramp import DEFAULT_SPEED_DEG_S

from .joints import ArmBusConfig


@RobotConfig.register_subclass("servoctl_arm")
@dataclass
class ServoctlArmConfig(RobotConfig, ArmBusConfig):
    # The most a target may be from where the joint is, degrees (one number, or one a joint).
    max_relative_target: float | dict[str, float] | None = None
    # The first actions after connect() ramp from where the arm is to what is asked, at
    # most this fast (deg/s); each joint follows freely once it is there. 0: no ramp (the
    # servo's top speed, 740 deg/s).
    ramp_speed_deg_s: float = DEFAULT_SPEED_DEG_S
    # This firmware's bus watchdog while connected (items 64, 65): a host silent this long
    # leaves the arm holding ("hold"), damped ("damp") or free ("release"). 0: left as it is.
    watchdog_ms: int = 500
    watchdog_action: str = "hold"
    disable_torque_on_disconnect: bool = True
    # The loop's frames a second (lerobot-teleoperate --fps, lerobot-record --dataset.fps):
    # the streamed setpoints' period.
    fps: float = 30.0
    cameras: dict[str, CameraConfig] = field(default_factory=dict)

    def __post_init__(self):
        """A setting that would drive the arm wrong is refused when the
        config is made: a negative max_relative_target moved every joint
        that far away from where it was, each frame, whatever the action."""
        super().__post_init__()
        cap = self.max_relative_target
        caps = [] if cap is None else list(cap.values()) if isinstance(cap, dict) else [cap]
        bad = [c for c in caps if not _distance(c)]
        if bad:
            raise ValueError(f"max_relative_target is degrees, 0 or more (one number, or one a joint), "
                             f"not {bad[0]!r}")
        if not (_number(self.fps) and self.fps > 0):
            raise ValueError(f"fps is the loop's frames a second, more than 0, not {self.fps!r}")


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _distance(x) -> bool:
    return _number(x) and x >= 0
