"""servoctl tune: the controller's gains from the identified drive train,
for a closed-loop bandwidth, with their margins; checked with a step on the
servo, and stored with the drive train (data items 80-88).

The identified drive train at the output (identify.py) is, with the duty d
as the input and the angle q as the output,

    J q'' = G d - D q',    G = K V / R,   D = K^2 / R + B

and the firmware's controller gives d = kp e + ki (integral of e) + kd
(v_planned - q') plus the feed-forward of the plan (which the drive items
carry). With the feedback alone, kp and kd place the closed loop's poles at
the natural frequency w = 2 pi f and damping zeta:

    kp = J w^2 / G,   kd = (2 zeta w J - D) / G

and the integral's zero sits at w / 4, well below, where it removes the
steady error a load leaves without shaping the step. The margins are the
open loop's, (kp + kd s + ki / s) G / (s (J s + D)) e^(-s T), with T the
1.5 ticks from a sample to its duty (the tick samples, the bridge holds the
duty until the next).

Units: the firmware's gains are Q15 duty per decidegree (kp), per
decidegree each 1 ms tick (ki), and per decidegree per tick (kd)."""
import math
from dataclasses import dataclass

from . import registers
from .errors import ServoError
from .loop_model import DECIDEG_RAD, Q15, TICK_S, _plant, _si, margins  # noqa: F401 (tune's own names too)

ZETA = 0.7
DEFAULT_MAX_HZ = 8.0      # no faster by default: the reference's factory gains are 8.4 Hz
RANGE_SHARE = 0.8         # the default stays this far inside the gains' item ranges
CHECK_TARGET_DECIDEG = 450
CHECK_MS = 500
CHECK_TOLERANCE_DECIDEG = 20  # the check's error 1.5 s on beyond which the tuning failed


@dataclass
class Tuning:
    bandwidth_hz: float
    zeta: float
    kp: int
    ki: int
    kd: int
    phase_margin_deg: float
    gain_margin_db: float
    crossover_hz: float
    items: dict            # data item name: value, the drive train (80-85) and the gains


def _firmware(kp_si: float, ki_si: float, kd_si: float) -> tuple:
    """SI gains (duty per rad, per rad s, per rad/s) in the firmware's units."""
    return (kp_si * Q15 * DECIDEG_RAD, ki_si * Q15 * DECIDEG_RAD * TICK_S, kd_si * Q15 * DECIDEG_RAD / TICK_S)


def gains_for(drive, bandwidth_hz: float, zeta: float = ZETA) -> tuple:
    """(kp, ki, kd) in firmware units, unrounded."""
    g, d, j = _plant(drive)
    w = 2.0 * math.pi * bandwidth_hz
    kp = j * w * w / g
    return _firmware(kp, kp * w / 4.0, max(0.0, (2.0 * zeta * w * j - d) / g))


def _most(name: str) -> int:
    return registers.find(name).high


def range_limit_hz(drive, zeta: float = ZETA) -> float:
    """The highest bandwidth whose kp and kd fit items 86 and 88."""
    lo, hi = 0.01, 200.0
    for _ in range(60):
        mid = math.sqrt(lo * hi)
        kp, ki, kd = gains_for(drive, mid, zeta)
        fits = kp <= _most("gain_kp") and kd <= _most("gain_kd") and ki <= _most("gain_ki")
        lo, hi = (mid, hi) if fits else (lo, mid)
    return lo


def drive_items(drive, gear_ratio: int) -> dict:
    """Items 80-85 from the drive train at the output, referred to the motor
    through the servo's gear ratio item (82; its sign is the direction,
    calibrate's, and stays): kt = K / ratio, the inertia and the viscous
    drag / ratio^2, the Coulomb drag / ratio."""
    if gear_ratio == 0:
        raise ServoError("gear_ratio is 0 (no feed-forward): set it to the servo's ratio first")
    n = float(abs(gear_ratio))
    values = {"motor_resistance": drive.resistance.value * 1e3,            # mOhm
              "torque_constant": drive.torque_constant.value / n * 1e6,    # uN m/A
              "rotor_inertia": drive.inertia.value / (n * n) * 1e10,       # mg cm^2
              "coulomb_friction": max(drive.coulomb.value, 0.0) / n * 1e7,  # 0.1 uN m
              "viscous_friction": max(drive.viscous.value, 0.0) / (n * n) * 1e10}  # 1e-10 N m s/rad
    out = {}
    for name, value in values.items():
        item = registers.find(name)
        v = int(round(value))
        if not item.low <= v <= item.high:
            raise ServoError(f"{name} would be {value:.4g} {item.unit}, outside {item.low}..{item.high}: "
                             f"set gear_ratio (now {gear_ratio}) to the servo's own ratio first (its sign kept)")
        out[name] = v
    return out


def tune(drive, gear_ratio: int, bandwidth_hz: float = 0.0) -> Tuning:
    """The items for the drive train at bandwidth_hz (0: the default, the
    lesser of DEFAULT_MAX_HZ and RANGE_SHARE of what the gains' ranges
    allow)."""
    limit = range_limit_hz(drive)
    if bandwidth_hz <= 0.0:
        bandwidth_hz = min(DEFAULT_MAX_HZ, RANGE_SHARE * limit)
    elif bandwidth_hz > limit:
        raise ServoError(f"{bandwidth_hz:g} Hz needs gains beyond items 86-88's ranges on this drive train: "
                         f"at most {limit:.2f} Hz")
    kp, ki, kd = (int(round(x)) for x in gains_for(drive, bandwidth_hz))
    ki = max(ki, 1)  # the integral stays on: a load's steady error goes
    pm, gm, fc = margins(drive, kp, ki, kd)
    items = {**drive_items(drive, gear_ratio), "gain_kp": kp, "gain_ki": ki, "gain_kd": kd}
    return Tuning(bandwidth_hz, ZETA, kp, ki, kd, pm, gm, fc, items)


def check_step(servo, sleep, target: int = CHECK_TARGET_DECIDEG, ms: int = CHECK_MS) -> tuple:
    """A move of target decidegrees from 0 in ms: (overshoot past the
    target, the error 1.5 s after it began), both in decidegrees, on the
    servo's clock."""
    servo.move(0, interval_ms=300)
    sleep(1.0)
    servo.move(target, interval_ms=ms)
    way = 1 if target >= 0 else -1
    angles = []
    for _ in range(75):
        sleep(0.02)
        angles.append(way * servo.read_motion().angle_decideg)
    return max(angles) - way * target, abs(angles[-1] - way * target)
