"""servoctl identify: the drive train's constants from open-loop duty steps.

The servo is driven open loop (DriveDuty, 0x46) at a few duties each way,
one step at a time from rest, and sampled through ReadMotion on the servo's
own clock. A brushed DC motor behind a gearbox, seen at the output
(K = kt x gear ratio, the drags at the output), obeys

    V d = R i + K w                 (the winding; its inductance's
                                     microseconds are below a sample)
    J w' = K i - C sgn(w) - B w     (the output)

so at each step's steady speed V d = R i + K w gives R and K, and
K i = C + B w gives the Coulomb and viscous drags; from rest the speed
rises as w_ss (1 - exp(-t / tau)) with tau = J / (K^2 / R + B), which gives
the inertia. Then two reversals each way at the lowest duty: the gears turn
back through their play (backlash) before the output, on the far side of
the encoder, follows; the play is the one that makes the model above, with
that play between it and the output, follow the recorded angle after the
reversal. Every fit is least squares (scipy), and each value is given
with its standard error. Last, a chirp (a duty sine swept from 0.5 to 8 Hz,
one short DriveDuty after another) checks the model across frequencies:
driven by the duty the bridge was given, it must follow the servo's speed. ReadMotion's duty is what the bridge was given
(after the current limit), so a step the limit clips is known and not used
for the inertia."""
import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from . import registers
from .errors import ServoError

DEFAULT_DUTIES = (0.15, 0.25, 0.35, 0.45)
DEFAULT_STEP_MS = 700   # the least; longer where the rise is slower (step_length_ms)
REST_POLL_S = 0.05    # how often come_to_rest looks at the horn
STEADY_FROM = 0.6     # the steady part of a step: its last 40 %
CLIP_TOLERANCE = 0.02
REVERSAL_WINDOW_S = 0.4   # the reversal's record the play is fitted over
REVERSAL_SUBSTEP_S = 0.00025
MAX_BACKLASH_DEG = 10.0
REVERSALS_EACH_WAY = 2
REVERSAL_HALF_MAX_MS = 9500  # DriveDuty takes 10 s at most
CHIRP_HZ = (0.5, 8.0)
CHIRP_S = 4.0
CHIRP_HOLD_MS = 40        # each DriveDuty of the chirp: released soon should the host stop
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


def record_step(servo, duty: float, step_ms: int, sleep) -> Step:
    """One open-loop step from rest, sampled until the output is released
    and has coasted a little; sleep(s) waits on the servo's (or the
    simulator's) clock."""
    first = servo.read_motion()
    servo.drive_duty(duty, step_ms)
    samples = []
    end_s = step_ms / 1000.0 + 0.05
    while True:
        snap = servo.read_motion()
        t = snap.seconds_since(first)
        samples.append(Sample.of(snap, t))
        if t > end_s:
            break
        if len(samples) > 20000:
            raise ServoError("the servo's clock did not advance during the step")
    if not any(s.duty != 0.0 for s in samples):
        held = ", ".join(registers.status_names(servo.read("status"))) or "nothing the status says"
        raise ServoError(f"the servo did not drive the step at duty {duty:+.2f}: held by {held} "
                         "(a protection holds the output: see items 39-43)")
    come_to_rest(servo, sleep)
    return Step(duty, samples)


def come_to_rest(servo, sleep, timeout_s: float = 10.0) -> None:
    """Damping (packet 9) until the horn is still, then released: released
    at once, a large inertia coasts for seconds, and the next step must
    start from rest."""
    servo.damping()
    still = 0
    waited = 0.0
    while still < 3:
        sleep(REST_POLL_S)
        waited += REST_POLL_S
        still = still + 1 if abs(servo.read_motion().velocity_decideg_s) < 5 else 0
        if waited > timeout_s:
            raise ServoError(f"the horn did not come to rest within {timeout_s:g} s of damping")
    servo.stop("release")


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


def _rise_tau(step: Step):
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
    taus = [tau for tau in (_rise_tau(s) for s in steps) if tau is not None]
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


def record_reversal(servo, duty: float, half_ms: int, sleep) -> Step:
    """From rest: duty for half_ms, then at once -duty for half_ms, sampled
    as a step is."""
    first = servo.read_motion()
    servo.drive_duty(duty, half_ms + 500)  # the reversal replaces it before it ends
    samples = []
    reversed_ = False
    while True:
        snap = servo.read_motion()
        t = snap.seconds_since(first)
        samples.append(Sample.of(snap, t))
        if not reversed_ and t >= half_ms / 1000.0:
            servo.drive_duty(-duty, half_ms)
            reversed_ = True
        if t > 2.0 * half_ms / 1000.0 + 0.05 or len(samples) > 40000:
            break
    come_to_rest(servo, sleep)
    return Step(duty, samples)


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


def _reversal_play(drive, step: Step):
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


def record_chirp(servo, duty: float, sleep) -> list:
    """The duty a sine of amplitude duty, its frequency swept from
    CHIRP_HZ[0] to [1] (exponentially) over CHIRP_S, a DriveDuty after each
    ReadMotion sample; the samples."""
    first = servo.read_motion()
    samples, phase, last = [], 0.0, 0.0
    f0, f1 = CHIRP_HZ
    while True:
        snap = servo.read_motion()
        t = snap.seconds_since(first)
        samples.append(Sample.of(snap, t))
        if t > CHIRP_S or len(samples) > 40000:
            break
        phase += 2.0 * math.pi * f0 * (f1 / f0) ** (t / CHIRP_S) * (t - last)
        last = t
        q15 = round(duty * math.sin(phase) * 32767) or 1  # DriveDuty takes no 0
        servo.drive_duty(q15 / 32767.0, CHIRP_HOLD_MS)
    come_to_rest(servo, sleep)
    return samples


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


def step_length_ms(servo, duty: float, sleep) -> int:
    """A step long enough to be steady for its last 40 %: 12 rise times,
    from a first step's rise (DEFAULT_STEP_MS at least, 10 s at most)."""
    probe = _rise_tau(record_step(servo, duty, DEFAULT_STEP_MS, sleep))
    if probe is None:
        return DEFAULT_STEP_MS
    return int(min(max(12.0 * probe[0] * 1000.0, DEFAULT_STEP_MS), 10000))


def identify(servo, sleep, duties=DEFAULT_DUTIES, step_ms: int = 0, progress=None) -> DriveTrain:
    """Steps at each duty, each way in turn (so the horn comes back), then
    the fit; step_ms 0: as the drive train's rise time asks
    (step_length_ms). progress(done, total) after each step."""
    supply_v = servo.read("voltage") / 1000.0
    if supply_v <= 0.5:
        raise ServoError(f"the supply reads {supply_v:.2f} V: identify needs the motor powered")
    if step_ms == 0:
        step_ms = step_length_ms(servo, duties[0], sleep)
        servo.drive_duty(-duties[0], DEFAULT_STEP_MS)  # back to about where it began
        sleep(DEFAULT_STEP_MS / 1000.0)
        come_to_rest(servo, sleep)
    plan = [d * sign for d in duties for sign in (1.0, -1.0)]
    reversals = (duties[0], -duties[0]) * REVERSALS_EACH_WAY
    total = len(plan) + len(reversals) + 1  # the steps, the reversals, the chirp
    steps = []
    for n, duty in enumerate(plan):
        steps.append(record_step(servo, duty, step_ms, sleep))
        if progress is not None:
            progress(n + 1, total)
    drive = fit(steps, supply_v)
    plays = []
    half_ms = min(step_ms, REVERSAL_HALF_MAX_MS)  # the first duty's DriveDuty outlasts it by 500 ms
    for n, duty in enumerate(reversals):
        play = _reversal_play(drive, record_reversal(servo, duty, half_ms, sleep))
        if play is not None:
            plays.append(play)
        if progress is not None:
            progress(len(plan) + n + 1, total)
    if plays:
        spread = float(np.std(plays, ddof=1) / math.sqrt(len(plays))) if len(plays) > 1 else math.radians(0.1)
        drive.backlash = Estimate(float(np.mean(plays)), spread)
    drive.chirp = chirp_error(drive, record_chirp(servo, duties[-1] * 2.0 / 3.0, sleep))
    if progress is not None:
        progress(total, total)
    return drive


def cmd_identify(bus, args):
    """servoctl identify ID: open-loop steps, the fit, a table with each
    value's standard error."""
    from .servo import Servo

    servo = Servo(bus, args.id)
    duties = tuple(args.duty * k / len(DEFAULT_DUTIES) for k in range(1, len(DEFAULT_DUTIES) + 1))
    print(f"servo {args.id}: open-loop steps at duties {', '.join(f'±{d:.2f}' for d in duties)}, then "
          "two reversals each way (the horn must turn freely: it goes round several times)", flush=True)

    def progress(done, total):
        print(f"  step {done}/{total}", flush=True)

    drive = identify(servo, bus.sleep, duties, args.step_ms, progress)
    print(f"drive train at the output, {drive.supply_v:.2f} V supply, inertia from {drive.steps_used} rises:")
    for name, e, unit in drive.rows():
        print(f"  {name:28s} {e.value:11.4g} {unit:10s} ± {e.percent():.2g} %")
    speed_error, angle_error = drive.chirp
    print(f"chirp {CHIRP_HZ[0]:g}-{CHIRP_HZ[1]:g} Hz at duty ±{duties[-1] * 2 / 3:.2f}: the model follows the "
          f"servo's speed within {100 * speed_error:.1f} % RMS (its angle within {math.degrees(angle_error):.2f} deg)")
    if args.mujoco:
        from . import actuator_model

        actuator_model.write(drive, args.mujoco)
        rms_deg, percent = actuator_model.match(args.mujoco, drive)
        print(f"mujoco model: {args.mujoco}; replaying the {len(drive.steps)} steps it follows the servo "
              f"within {rms_deg:.2f} deg RMS ({percent:.2f} % of a step's travel)")
    return 0
