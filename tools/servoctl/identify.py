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
for the inertia.

The experiments are here; the fits are identify_fit.py's, the command's
report identify_report.py's."""
import math

from . import extras, registers
from .errors import ServoError

try:
    import numpy as np
except ModuleNotFoundError as e:  # the extra servoctl[identify]
    raise extras.missing(e) from None

from .identify_fit import DriveTrain, Estimate, Sample, Step, chirp_error, fit, reversal_play, rise_tau

DEFAULT_DUTIES = (0.15, 0.25, 0.35, 0.45)
DEFAULT_STEP_MS = 700   # the least; longer where the rise is slower (step_length_ms)
REST_POLL_S = 0.05    # how often come_to_rest looks at the horn
REVERSALS_EACH_WAY = 2
REVERSAL_HALF_MAX_MS = 9500  # DriveDuty takes 10 s at most
BACK_MS = 600              # the closed-loop move back to where identify (or calibrate) began
BACK_TIMEOUT_S = 8.0
CHIRP_HZ = (0.5, 8.0)
CHIRP_S = 4.0
CHIRP_HOLD_MS = 40        # each DriveDuty of the chirp: released soon should the host stop


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


def step_length_ms(servo, duty: float, sleep) -> int:
    """A step long enough to be steady for its last 40 %: 12 rise times,
    from a first step's rise (DEFAULT_STEP_MS at least, 10 s at most)."""
    probe = rise_tau(record_step(servo, duty, DEFAULT_STEP_MS, sleep))
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
    start = servo.read_motion().angle_decideg
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
        play = reversal_play(drive, record_reversal(servo, duty, half_ms, sleep))
        if play is not None:
            plays.append(play)
        if progress is not None:
            progress(len(plan) + n + 1, total)
    if plays:
        spread = float(np.std(plays, ddof=1) / math.sqrt(len(plays))) if len(plays) > 1 else math.radians(0.1)
        drive.backlash = Estimate(float(np.mean(plays)), spread)
    drive.chirp = chirp_error(drive, record_chirp(servo, duties[-1] * 2.0 / 3.0, sleep))
    back_to(servo, sleep, start)
    if progress is not None:
        progress(total, total)
    return drive


def back_to(servo, sleep, start_decideg: int) -> None:
    """The horn closed loop back where identify found it (it ended up to
    a quarter turn away, outside the limits it had started within), then
    released."""
    come_to_rest(servo, sleep)
    # Near it is enough: a drive train that is not yet tuned may hold a few degrees off.
    return_to(servo, sleep, start_decideg, within_decideg=50, insist=False)
    servo.stop("release")


def return_to(servo, sleep, start_decideg: int, within_decideg: int = 3, insist: bool = True) -> None:
    """A closed-loop move to start_decideg, waited for: within it and still
    (a soft start, item 49, may stretch it to item 50's 3 s); not there in
    BACK_TIMEOUT_S, ServoError if insist."""
    servo.move(start_decideg, interval_ms=BACK_MS)
    waited = 0.0
    while True:
        sleep(0.05)
        waited += 0.05
        snap = servo.read_motion()
        if abs(snap.angle_decideg - start_decideg) <= within_decideg and abs(snap.velocity_decideg_s) < 20:
            return
        if waited > BACK_TIMEOUT_S:
            if not insist:
                return
            raise ServoError(f"the horn did not come back to {start_decideg / 10:.1f} deg within "
                             f"{BACK_TIMEOUT_S:g} s (it is at {snap.angle_decideg / 10:.1f})")
