"""servoctl_arm's settings (docs/lerobot.md)."""
import math
from dataclasses import dataclass, field

from lerobot.cameras import CameraConfig
from lerobot.robots.config import RobotConfig
from servoctl import registers
from servoctl.arm_ramp import DEFAULT_SPEED_DEG_S
from servoctl.arm import check_settings
from servoctl.errors import UsageError, ValueOutOfRange
from servoctl.setpoints import PERIOD_RANGE_MS, check_ids

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
        """A setting that would drive the arm wrong, or that connect() would
        refuse later in other words, is refused when the config is made: a
        negative max_relative_target moved every joint that far away from
        where it was, each frame, whatever the action."""
        super().__post_init__()
        if not (isinstance(self.joints, dict) and self.joints and all(isinstance(n, str) for n in self.joints)
                and all(isinstance(i, int) and not isinstance(i, bool) for i in self.joints.values())):
            raise ValueError(f"joints is a joint's name -> its servo ID for each joint, not {self.joints!r}")
        try:
            check_ids(list(self.joints.values()))
        except (UsageError, ValueOutOfRange) as e:
            raise ValueError(f"joints name servo IDs, each once: {e}") from None
        cap = self.max_relative_target
        caps = [] if cap is None else list(cap.values()) if isinstance(cap, dict) else [cap]
        bad = [c for c in caps if not _distance(c)]
        if bad:
            raise ValueError(f"max_relative_target is degrees, 0 or more (one number, or one a joint), "
                             f"not {bad[0]!r}")
        unknown = sorted(map(repr, set(cap) - set(self.joints))) if isinstance(cap, dict) else []
        if unknown:
            raise ValueError(f"max_relative_target names joints the arm does not have: {', '.join(unknown)} "
                             f"(its joints: {', '.join(self.joints)})")
        slowest, fastest = (1000 / ms for ms in reversed(PERIOD_RANGE_MS))
        if not (_number(self.fps) and slowest <= self.fps <= fastest):
            raise ValueError(f"fps is the loop's frames a second, {slowest:g} to {fastest:g} (a period of "
                             f"{PERIOD_RANGE_MS[0]} to {PERIOD_RANGE_MS[1]} ms), not {self.fps!r}")
        try:  # the firmware, the watchdog and the ramp as Arm checks them
            check_settings(self.joints, self.fps, self.firmware, self.watchdog_ms, self.watchdog_action,
                           self.ramp_speed_deg_s)
        except UsageError as e:
            raise ValueError(str(e)) from None
        if self.watchdog_ms and self.watchdog_ms < 2000 / self.fps:
            raise ValueError(f"watchdog_ms {self.watchdog_ms} would act between frames: a frame comes every "
                             f"{1000 / self.fps:g} ms at fps {self.fps:g}, and watchdog_ms must be at least two "
                             f"frames ({2000 / self.fps:g} ms); set a longer watchdog_ms, a higher fps, or 0")
        if isinstance(self.baud, bool) or self.baud not in registers.BAUD_RATES.values():
            raise ValueError(f"baud is one of {', '.join(map(str, registers.BAUD_RATES.values()))}, not {self.baud!r}")


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _distance(x) -> bool:
    return _number(x) and x >= 0
