"""servoctl's commands that move one servo: move, wheel, damping, stop,
origin."""
import sys

from . import args as args_
from .. import checks, frame, outcome
from ..drive_guard import check_horn_free, narrowed_limits
from ..errors import Refused
from ..servo import Servo


def cmd_move(bus, args):
    s = Servo(bus, args.id)
    request = args_.move_request(args)
    asked = args_.decideg(args.angle)
    where = frame.check_target(s, asked, args.multi_turn)
    if args.velocity is not None and (why := checks.speed_warning(args.velocity, s.read("voltage"))):
        print(f"servoctl: {why}", file=sys.stderr)
    plan = outcome.plan_move(s, asked, request, where) if args.wait else None
    s.send_move(asked, request)
    outcome.taken(s, "the move")
    if not args.wait:
        return 0
    result = outcome.wait_for_arrival(s, plan, args.tolerance, args.timeout_s)
    if not result.arrived:
        raise Refused(f"servo {args.id}: {result.reason}")
    print(f"servo {args.id}: at {result.angle / 10:.1f} deg after {result.took_s * 1000:.0f} ms "
          f"({outcome.planned_text(plan, result.took_s)})")
    return 0


def cmd_wheel(bus, args):
    s = Servo(bus, args.id)
    if args.action != "stop":  # a wheel turns through any angle limits
        check_horn_free(s, f"wheel {args.action}", args.past_limits, "turns the horn through them (a wheel keeps to none)",
                        "If the horn is free, give --past-limits (servoctl ui: tick 'horn free')")
    s.wheel(args.action, args.speed, args.value, args.cw)
    outcome.taken(s, f"wheel {args.action}")
    return 0


def cmd_damping(bus, args):
    s = Servo(bus, args.id)
    s.damping(args.power)
    outcome.taken(s, "damping")
    return 0


def cmd_stop(bus, args):
    s = Servo(bus, args.id)
    s.stop(args.mode, args.power)
    outcome.taken(s, f"stop ({args.mode})")
    return 0


def cmd_origin(bus, args):
    s = Servo(bus, args.id)
    if not args.reset_turns:  # the limits' numbers would name other horn positions
        check_horn_free(s, "origin", args.past_limits,
                        "makes here angle 0 until power-up, and the limits' numbers would then name other horn "
                        "positions (the joint's range moved by the angle here)",
                        f"'servoctl calibrate {s.id} --past-limits' moves the stored zero and the limits together; "
                        "--past-limits makes the origin anyway")
    joint = None if args.reset_turns else narrowed_limits(s)  # --past-limits: said what it does to them
    was = s.read_motion().angle_decideg if joint is not None else 0
    if args.reset_turns:
        s.reset_multi_turn()
    else:
        s.set_origin()
    bus.sleep(0.01)
    try:
        outcome.taken(s, "a new origin")
    except Refused:
        raise Refused(f"servo {args.id} refused a new origin: release it first with "
                      f"'servoctl stop {args.id}'") from None
    angle, turns = s.multi_turn_angle()
    print(f"servo {args.id}: now {angle / 10:.1f} deg, {turns} turns")
    if joint is not None:
        low, high = joint
        print(f"servo {args.id}: its angle limits keep their numbers, {low / 10:.1f}..{high / 10:.1f} deg: until "
              f"power-up they are the horn's old {(low + was) / 10:.1f}..{(high + was) / 10:.1f} deg")
    return 0


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "move": cmd_move,
    "wheel": cmd_wheel,
    "damping": cmd_damping,
    "stop": cmd_stop,
    "origin": cmd_origin,
}
