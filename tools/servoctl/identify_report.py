"""servoctl identify ID: the experiment (identify.py), then a table of the
fitted values with their standard errors, the chirp's match, and with
--mujoco the actuator model written and replayed."""
import math

from .identify import CHIRP_HZ, DEFAULT_DUTIES, identify


def cmd_identify(bus, args):
    """servoctl identify ID: open-loop steps, the fit, a table with each
    value's standard error."""
    from .servo import Servo

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
        from . import actuator_model

        actuator_model.write(drive, args.mujoco)
        rms_deg, percent = actuator_model.match(args.mujoco, drive)
        print(f"mujoco model: {args.mujoco}; replaying the {len(drive.steps)} steps it follows the servo "
              f"within {rms_deg:.2f} deg RMS ({percent:.2f} % of a step's travel)")
    return 0
