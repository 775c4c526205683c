"""The fits of servoctl identify to its records (identify.py, whose
docstring gives the model): the steady speeds' least squares for R, K
and the drags, the rises' for the inertia, the reversals' for the
play, and the model against the chirp. Each value with its standard
error."""
import math
from dataclasses import dataclass

from . import extras

try:
    import numpy as np
    from scipy import optimize
except ModuleNotFoundError as e:  # the extra servoctl[identify]
    raise extras.missing(e) from None

from .errors import ServoError

STEADY_FROM = 0.6     # the steady part of a step: its last 40 %
CLIP_TOLERANCE = 0.02
REVERSAL_WINDOW_S = 0.4   # the reversal's record the play is fitted over
REVERSAL_SUBSTEP_S = 0.00025
MAX_BACKLASH_DEG = 10.0
SPEED_SMOOTHING = 5       # samples (17 ms) the speeds compared are averaged over


@dataclass
class Sample:
    t: float          # s, the servo's clock from the step's command
    angle: float      # rad, output
    current: float    # A, magnitude (item 2)
    duty: float       # of the supply, as the bridge was given it

    @classmethod
    def of(cls, snap, t: float) -> "Sample":
        """A ReadMotion snapshot taken t into the record."""
        return cls(t, math.radians(snap.angle_decideg / 10.0), snap.current_ma / 1000.0, snap.duty_q15 / 32767.0)


@dataclass
class Step:
    duty: float       # commanded
    samples: list


@dataclass
class Estimate:
    value: float
    sigma: float      # standard error

    def percent(self) -> float:
        return 100.0 * self.sigma / abs(self.value) if self.value else math.inf


@dataclass
class DriveTrain:
    """At the output: K = kt x ratio (N m/A), R (ohm), J (kg m^2), C (N m),
    B (N m s/rad); supply_v as measured."""
    torque_constant: Estimate
    resistance: Estimate
    inertia: Estimate
    coulomb: Estimate
    viscous: Estimate
    supply_v: float
    steps_used: int
    steps: list = None  # the recorded steps the fit came from
    backlash: Estimate = None  # rad at the output; None where no reversal was recorded
    chirp: tuple = None  # the model against a chirp: (speed's RMS error, fraction; angle's, rad)

    def rows(self):
        rows = [("torque constant x ratio", self.torque_constant, "N m/A"),
                ("resistance", self.resistance, "ohm"),
                ("inertia at the output", self.inertia, "kg m^2"),
                ("Coulomb drag at the output", self.coulomb, "N m"),
                ("viscous drag at the output", self.viscous, "N m s/rad")]
        if self.backlash is not None:
            rows.append(("backlash at the output", Estimate(math.degrees(self.backlash.value),
                                                           math.degrees(self.backlash.sigma)), "deg"))
        return rows


def _driven(step: Step):
    return [s for s in step.samples if s.duty != 0.0]


def _steady(step: Step):
    """(applied duty, speed rad/s, signed current A) over the step's steady part."""
    driven = _driven(step)
    if len(driven) < 8:
        raise ServoError(f"the step at duty {step.duty:+.2f} has {len(driven)} driven samples: too few "
                         "(a faster bus, or longer steps)")
    t0, t1 = driven[0].t, driven[-1].t
    steady = [s for s in driven if s.t >= t0 + STEADY_FROM * (t1 - t0)]
    ts = np.array([s.t for s in steady])
    angles = np.array([s.angle for s in steady])
    speed = np.polyfit(ts, angles, 1)[0]
    sign = 1.0 if step.duty > 0 else -1.0
    return (float(np.mean([s.duty for s in steady])), float(speed),
            sign * float(np.mean([s.current for s in steady])))


def _linear(rows, rhs):
    """Least squares rows @ x = rhs: x and its standard errors."""
    a, b = np.asarray(rows, float), np.asarray(rhs, float)
    x, *_ = np.linalg.lstsq(a, b, rcond=None)
    dof = max(len(b) - len(x), 1)
    residual = float(np.sum((a @ x - b) ** 2)) / dof
    cov = residual * np.linalg.pinv(a.T @ a)
    return x, np.sqrt(np.maximum(np.diag(cov), 0.0))


def rise_tau(step: Step):
    """tau (s) and its standard error from the angle's rise from rest, or
    None where the current limit clipped the duty during the rise."""
    driven = _driven(step)
    t_on = driven[0].t
    rise = [s for s in step.samples if s.t <= t_on + 0.5 * (driven[-1].t - t_on)]
    if any(abs(s.duty - step.duty) > CLIP_TOLERANCE * abs(step.duty) for s in rise if s.duty != 0.0):
        return None
    t = np.array([s.t for s in rise])
    angle = np.array([s.angle for s in rise])

    way = math.copysign(1.0, step.duty)

    def model(t, a0, t0, tau, w, play):
        # The gears' travel from rest; the output, beyond the encoder, stays
        # until they have crossed what play there was, then goes with them.
        x = np.maximum(t - t0, 0.0)
        gears = w * (x - tau * (1.0 - np.exp(-x / tau)))
        return a0 + way * np.maximum(way * gears - play, 0.0)

    w_guess = (angle[-1] - angle[0]) / max(t[-1] - t[0], 1e-3)
    guess = (angle[0], t_on - 0.002, 0.02, w_guess, 1e-4)
    bounds = ([-np.inf, t[0] - 0.05, 1e-4, -np.inf, 0.0],
              [np.inf, t_on + 0.01, 5.0, np.inf, math.radians(MAX_BACKLASH_DEG)])
    params, cov = optimize.curve_fit(model, t, angle, p0=guess, bounds=bounds, maxfev=20000)
    return float(params[2]), float(math.sqrt(max(cov[2, 2], 0.0)))


def fit(steps, supply_v: float) -> DriveTrain:
    """The drive train from recorded steps (at least two each way)."""
    steady = [_steady(s) for s in steps]
    # V d = R i + K w
    (r, k), (sr, sk) = _linear([[i, w] for _, w, i in steady], [supply_v * d for d, _, _ in steady])
    # K i = C sgn(w) + B w
    (c, b), (sc, sb) = _linear([[math.copysign(1.0, w), w] for _, w, _ in steady], [k * i for _, _, i in steady])
    taus = [tau for tau in (rise_tau(s) for s in steps) if tau is not None]
    if not taus:
        raise ServoError("the current limit clipped every step's rise: lower the duties, or raise the "
                         "power limit (item 42) for the identification")
    damping = k * k / r + b
    tau = float(np.mean([t for t, _ in taus]))
    spread = float(np.std([t for t, _ in taus], ddof=1) / math.sqrt(len(taus))) if len(taus) > 1 else taus[0][1]
    j = tau * damping
    sj = j * math.hypot(spread / tau, math.hypot(2 * sk / k, sr / r) * (k * k / r) / damping)
    return DriveTrain(Estimate(k, sk), Estimate(r, sr), Estimate(j, sj), Estimate(c, sc), Estimate(b, sb),
                      supply_v, len(taus), list(steps))


def _follow(drive, samples, play: float, w0: float, lead: float, switch_t: float) -> np.ndarray:
    """The output's angle at each sample, from the identified model driven
    by the samples' duty (each held back to the sample before it; the first
    interval's new duty from switch_t, when the reversal came), the gears
    leading the output by lead x play / 2 and turning at w0 at the first
    sample, with play between the gears and the output (which stays put in
    it)."""
    k, r, j = drive.torque_constant.value, drive.resistance.value, drive.inertia.value
    g, d, c = k * drive.supply_v / r, k * k / r + drive.viscous.value, max(drive.coulomb.value, 0.0)
    half = 0.5 * play
    gap, v, out = lead * half, w0, samples[0].angle
    predicted = [out]
    for now, after in zip(samples, samples[1:]):
        span = after.t - now.t
        n = max(1, int(span / REVERSAL_SUBSTEP_S))
        h = span / n
        for m in range(n):
            duty = now.duty if now is samples[0] and now.t + (m + 0.5) * h < switch_t else after.duty
            push = g * duty
            if v == 0.0 and abs(push) <= c:
                continue  # static friction holds
            direction = math.copysign(1.0, v if v != 0.0 else push)
            before = v
            v += (push - d * v - c * direction) / j * h
            if before * v < 0.0:
                v = 0.0  # friction stops, it does not reverse
            ahead = gap + v * h
            gap = min(max(ahead, -half), half)
            out += ahead - gap
        predicted.append(out)
    return np.array(predicted)


def reversal_play(drive, step: Step):
    """The play (rad) that lets the model follow the recorded angle from
    just before the reversal on, or None where the record is too short. The
    reversal's moment within its sample interval is fitted with it."""
    s = step.samples
    way = math.copysign(1.0, step.duty)
    at = next((i for i, x in enumerate(s) if x.duty * way < 0.0), None)
    if at is None or at < 12:
        return None
    before = s[at - 10:at]
    w0 = float(np.polyfit([x.t for x in before], [x.angle for x in before], 1)[0])
    end = next((i for i in range(at, len(s)) if s[i].t > s[at].t + REVERSAL_WINDOW_S or s[i].duty == 0.0), len(s))
    window = s[at - 1:end]
    if len(window) < 20:
        return None
    recorded = np.array([x.angle for x in window])
    t0, t1 = window[0].t, window[1].t

    def misfit(x):
        play = min(max(x[0], 0.0), math.radians(MAX_BACKLASH_DEG))
        switch_t = t0 + min(max(x[1], 0.0), 1.0) * (t1 - t0)
        return float(np.sqrt(np.mean((_follow(drive, window, play, w0, way, switch_t) - recorded) ** 2)))

    best = None
    for start in (0.25, 0.75):  # two starts: the reversal early or late in its interval
        found = optimize.minimize(misfit, x0=[math.radians(1.0), start], method="Nelder-Mead",
                                  options={"xatol": 1e-5, "fatol": 1e-9, "maxiter": 400})
        best = found if best is None or found.fun < best.fun else best
    return min(max(float(best.x[0]), 0.0), math.radians(MAX_BACKLASH_DEG))


def chirp_error(drive, samples) -> tuple:
    """The rigid model driven by the recorded duty from the first sample:
    (the speed's RMS error over its RMS, the angle's RMS error in rad)."""
    predicted = _follow(drive, samples, 0.0, 0.0, 1.0, samples[0].t)
    t = np.array([s.t for s in samples])
    angle = np.array([s.angle for s in samples])
    kernel = np.ones(SPEED_SMOOTHING) / SPEED_SMOOTHING
    speed = np.convolve(np.gradient(angle, t), kernel, mode="same")
    model = np.convolve(np.gradient(predicted, t), kernel, mode="same")
    rms = float(np.sqrt(np.mean(speed ** 2)))
    return (float(np.sqrt(np.mean((model - speed) ** 2))) / rms if rms > 0 else math.inf,
            float(np.sqrt(np.mean((predicted - angle) ** 2))))
