"""servoctl identify, tune and calibrate ID, as they print: identify's
experiment (identify.py), then a table of the fitted values with their
standard errors, the chirp's match, and with --mujoco the actuator model
written and replayed; tune's gains and margins (tune.py), written and a
step checked; calibrate's findings (calibrate.py). scipy (identify's fits)
is loaded with this module: cmd_drive imports it for these commands alone."""
import math

from .. import extras
from ..calibrate import PUSH_DUTY, calibrate
from ..errors import ServoError
from ..identify import CHIRP_HZ, DEFAULT_DUTIES, identify
from ..putback import PutBack
from ..servo import Servo
from ..tune import CHECK_MS, CHECK_TARGET_DECIDEG, CHECK_TOLERANCE_DECIDEG, check_step, tune


def cmd_identify(bus, args):
    """servoctl identify ID: open-loop steps, the fit, a table with each
    value's standard error."""
    if args.mujoco:
        extras.require("mujoco")  # the model is made after the experiment: refused before it
    servo = Servo(bus, args.id)
    duties = tuple(args.duty * k / len(DEFAULT_DUTIES) for k in range(1, len(DEFAULT_DUTIES) + 1))
    print(f"servo {args.id}: open-loop steps at duties {', '.join(f'±{d:.2f}' for d in duties)}, then "
          "two reversals each way (the horn must turn freely: some 120 deg of travel on the reference)", flush=True)

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
        from .. import actuator_model

        actuator_model.write(drive, args.mujoco)
        rms_deg, percent = actuator_model.match(args.mujoco, drive)
        print(f"mujoco model: {args.mujoco}; replaying the {len(drive.steps)} steps it follows the servo "
              f"within {rms_deg:.2f} deg RMS ({percent:.2f} % of a step's travel)")
    return 0


def cmd_tune(bus, args):
    """servoctl tune ID: identify, the gains, their margins; unless
    --dry-run, the items written (each kept in flash) and a step checked."""
    servo = Servo(bus, args.id)
    duties = tuple(args.duty * k / len(DEFAULT_DUTIES) for k in range(1, len(DEFAULT_DUTIES) + 1))
    print(f"servo {args.id}: identifying (open-loop steps; the horn must turn freely)", flush=True)
    drive = identify(servo, bus.sleep, duties, 0, lambda done, total: print(f"  step {done}/{total}", flush=True))
    t = tune(drive, servo.read("gear_ratio"), args.bandwidth)
    print(f"gains for {t.bandwidth_hz:.2f} Hz, damping {t.zeta}: kp {t.kp}, ki {t.ki}, kd {t.kd}")
    print(f"  phase margin {t.phase_margin_deg:.0f} deg, gain margin {t.gain_margin_db:.1f} dB, "
          f"crossover {t.crossover_hz:.2f} Hz")
    for name, value in t.items.items():
        print(f"  {name:18s} {value}")
    if args.dry_run:
        print("dry run: nothing written")
        return 0
    # Refused, nothing written, if the loop they make would not be stable. Kept
    # only once the check ran: one cut short (a Ctrl-C, the ui's STOP ALL at a
    # step that looked wrong, a servo gone) puts back the items the servo had.
    with PutBack(servo, "tune") as kept:
        kept.write_drive(t.items)
        over, error = check_step(servo, bus.sleep)
        if error > CHECK_TOLERANCE_DECIDEG:  # put back: gains that do not arrive are not kept as tuned
            raise ServoError(f"the check's {CHECK_TARGET_DECIDEG / 10:g} deg move ended {error / 10:.1f} deg "
                             f"from its target 1.5 s on (more than {CHECK_TOLERANCE_DECIDEG / 10:g}): a load, "
                             "a stop or an angle limit in its way? The items it had are put back")
    print(f"written and kept; a {CHECK_TARGET_DECIDEG / 10:g} deg move in {CHECK_MS} ms: overshoot "
          f"{max(over, 0) / 10:.1f} deg, {error / 10:.1f} deg from the target 1.5 s on")
    return 0


def cmd_calibrate(bus, args):
    """servoctl calibrate ID: the current's zero, the direction, the zero;
    each stored as it is found."""
    servo = Servo(bus, args.id)
    where = "" if args.keep_zero else " (the horn at its zero mark: its position now becomes angle 0)"
    print(f"servo {args.id}: calibrating with the horn free{where}", flush=True)
    c = calibrate(servo, bus.sleep, args.keep_zero)
    print(f"  current amplifier's zero  {c.current_zero} ADC counts (item 91)")
    print(f"  direction                 {'reversed: the bridge is driven the other way' if c.reversed else 'as wired'}"
          f" (gear_ratio {c.gear_ratio}); a push at duty {PUSH_DUTY} turns the horn "
          f"+{c.push_decideg / 10:.1f} deg")
    if c.encoder_zero is None:
        print("  zero                      kept")
    else:
        print(f"  zero                      encoder count {c.encoder_zero} (item 90): angle 0 here, "
              "now and after every power-up")
    if c.limits is not None:
        (low, high), (new_low, new_high) = c.limits
        print(f"  angle limits              {low / 10:.1f}..{high / 10:.1f} deg from the old zero are "
              f"{new_low / 10:.1f}..{new_high / 10:.1f} from the new: the same horn positions")
    return 0
