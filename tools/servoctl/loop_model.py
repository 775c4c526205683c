"""The loop tune designs for and stability.py checks: the drive train at the
output (J q'' = G d - D q', G = K V / R, D = K^2 / R + B) under the
firmware's PID with 1.5 ticks of delay (tune.py's docstring)."""
import cmath
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


def frequencies(lo: float = -1.0, hi: float = 4.5, n: int = 20000) -> list:
    """The rad/s margins() looks at: n points, evenly spaced in log10 from
    10^lo to 10^hi (numpy's logspace, to the last bit)."""
    step = (hi - lo) / (n - 1)
    return [10.0 ** (i * step + lo) for i in range(n - 1)] + [10.0 ** hi]


_W = frequencies()


def margins(drive, kp: float, ki: float, kd: float) -> tuple:
    """(phase margin in degrees, gain margin in dB, gain crossover in Hz) of
    the loop with these firmware gains, read off its frequency response at
    _W: the gain crossover is the first point below unity gain; the phase
    there, unwrapped from the lowest frequency, gives the phase margin, and
    the gain at the first point from there whose phase reaches -180 deg
    the gain margin (none: infinite). The delay makes the loop's
    characteristic equation transcendental, so no Routh-Hurwitz table: the
    response point by point, in plain Python (the library needs only
    pyserial), the same figures numpy's arrays gave (tests/test_stability.py)."""
    g, d, j = _plant(drive)
    kp_si, ki_si, kd_si = _si(kp, ki, kd)
    crossing, pm, unwrap, last = None, math.nan, 0.0, None
    for i, w in enumerate(_W):
        s = complex(0.0, w)
        loop = (kp_si + kd_si * s + ki_si / s) * g / (s * (j * s + d)) * cmath.exp(-s * DELAY_S)
        phase = cmath.phase(loop)
        if last is not None:  # numpy's unwrap: a step beyond pi is taken the short way round
            step = phase - last
            if abs(step) >= math.pi:
                short = (step + math.pi) % (2.0 * math.pi) - math.pi
                if short == -math.pi and step > 0:
                    short = math.pi
                unwrap += short - step
        last = phase
        phase_deg = math.degrees(phase + unwrap)
        if crossing is None and abs(loop) < 1.0:
            crossing, pm = i, 180.0 + phase_deg
        if crossing is not None and phase_deg <= -180.0:
            return pm, -20.0 * math.log10(abs(loop)), _W[crossing] / (2.0 * math.pi)
    if crossing is None:
        return math.nan, math.nan, math.nan
    return pm, math.inf, _W[crossing] / (2.0 * math.pi)
