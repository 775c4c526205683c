"""The loop tune designs for and stability.py checks: the drive train at the
output (J q'' = G d - D q', G = K V / R, D = K^2 / R + B) under the
firmware's PID with 1.5 ticks of delay (tune.py's docstring)."""
import math

TICK_S = 0.001
DECIDEG_RAD = math.pi / 1800.0
Q15 = 32768.0
DELAY_S = 1.5 * TICK_S


def _plant(drive):
    k, r, b = drive.torque_constant.value, drive.resistance.value, drive.viscous.value
    return k * drive.supply_v / r, k * k / r + b, drive.inertia.value  # G, D, J


def _si(kp: float, ki: float, kd: float) -> tuple:
    return kp / (Q15 * DECIDEG_RAD), ki / (Q15 * DECIDEG_RAD * TICK_S), kd * TICK_S / (Q15 * DECIDEG_RAD)


def margins(drive, kp: float, ki: float, kd: float) -> tuple:
    """(phase margin in degrees, gain margin in dB, gain crossover in Hz) of
    the loop with these firmware gains. numpy is loaded here, by the drive
    items' check alone: servoctl's library needs only pyserial."""
    import numpy as np

    g, d, j = _plant(drive)
    kp_si, ki_si, kd_si = _si(kp, ki, kd)
    w = np.logspace(-1, 4.5, 20000)
    s = 1j * w
    loop = (kp_si + kd_si * s + ki_si / s) * g / (s * (j * s + d)) * np.exp(-s * DELAY_S)
    mag, phase = np.abs(loop), np.unwrap(np.angle(loop))
    phase_deg = np.degrees(phase)
    below = np.nonzero(mag < 1.0)[0]
    if below.size == 0:
        return math.nan, math.nan, math.nan
    c = below[0]
    pm = 180.0 + phase_deg[c]
    after = np.nonzero(phase_deg[c:] <= -180.0)[0]
    gm = -20.0 * math.log10(mag[c + after[0]]) if after.size else math.inf
    return pm, gm, w[c] / (2.0 * math.pi)
