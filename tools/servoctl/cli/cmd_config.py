"""servoctl's commands on a servo's settings: the config store's health
(store) and the user area by name (config get, set, dump, save, load,
reset, diff)."""
import json

from . import args as args_
from .. import config_diff, config_file, group, link_rate, registers, units
from ..drive_guard import narrowed_limits
from ..errors import NotSent, UsageError
from ..servo import Servo


def cmd_store(bus, args):
    """ReadStore: the config store's health, and what flash work cost the
    bus (answers dropped, bytes lost): a host that missed an answer, or
    whose broadcast a servo may have missed, learns it here."""
    h = Servo(bus, args.id).read_store()
    if args.json:
        print(json.dumps({"id": h.id, "flags": h.flag_names(), "records": h.records,
                          "page_erases": h.page_erases, "rated_cycles": h.rated_cycles,
                          "budget": h.budget, "op_seconds": h.op_seconds, "failures": h.failures,
                          "answers_dropped": h.answers_dropped, "bytes_lost": h.bytes_lost}))
        return 0
    print(f"servo {args.id}: config store")
    print(f"  state            {', '.join(h.flag_names()) or 'saved'}")
    print(f"  records          {h.records} (wear budget {h.budget} by now)")
    print(f"  page erases      {h.page_erases} of {h.rated_cycles} rated")
    print(f"  operating time   {h.op_seconds} s")
    print(f"  failed saves     {h.failures}")
    print(f"  answers dropped  {h.answers_dropped} (requests that arrived during a flash erase: "
          f"carried out, not answered)")
    print(f"  bytes lost       {h.bytes_lost}")
    return 0


def _shown(item, raw: int, as_raw: bool) -> str:
    if as_raw:
        return f"{raw}{' ' + item.unit if item.unit else ''}"
    return units.show(item, raw)


def _print_config(values: dict, as_raw: bool):
    for item in registers.STORED + registers.RAM:
        if item.name in values:
            ram = "  (RAM: lost at power-up)" if item in registers.RAM else ""
            print(f"  {item.id:2d} {item.name:<18} {_shown(item, values[item.name], as_raw)}{ram}")


def cmd_config_diff(bus, args):
    pairs = config_diff.pair(config_diff.resolve(bus, args.target), config_diff.resolve(bus, args.other))
    if not pairs:
        raise UsageError("nothing to compare: no entry of one side has a serial number or ID of the other")
    found = []
    for a, b in pairs:
        differ = config_diff.differences(a, b)
        found.append(differ)
        if args.json:
            print(json.dumps({"a": a.label, "b": b.label, "differ": {
                k: [config_diff.shown(k, x), config_diff.shown(k, y)] for k, (x, y) in differ.items()}}))
            continue
        print(f"{a.label} | {b.label}: " + (f"{len(differ)} item(s) differ" if differ else "the same"))
        for name, (x, y) in differ.items():
            print(f"  {name:<18} {config_diff.shown(name, x):>14} | {config_diff.shown(name, y)}")
    return 1 if any(found) else 0


def joint_range(values: dict) -> bool:
    """A file's angle limits are a joint's: on, and narrower than the factory's."""
    factory = {n: registers.find(n).default for n in ("angle_limit_on", "angle_min", "angle_max")}
    on = values.get("angle_limit_on", factory["angle_limit_on"])
    return bool(on) and (values.get("angle_min", factory["angle_min"]) > factory["angle_min"] or
                         values.get("angle_max", factory["angle_max"]) < factory["angle_max"])


def cmd_config(bus, args):
    if args.action == "diff":
        return cmd_config_diff(bus, args)
    s = Servo(bus, args.id)
    if args.action == "get":
        item = registers.find(args.name)
        raw = s.read(item.id)
        if args.json:
            counts = units.parts(item, raw)  # item 73's four counts, by name
            print(json.dumps({"id": item.id, "name": item.name, "raw": raw, "value": units.show(item, raw),
                              **({"counts": counts} if counts else {})}))
        else:
            print(f"{item.name} = {_shown(item, raw, args.raw)}")
    elif args.action == "set":
        item = registers.find(args.name)
        value = args_.raw_value(item, args.value) if args.raw else units.to_raw(item, args.value)
        if item.name == "servo_id":
            group.id_is_free(bus, args.id, value)
        # The servo would refuse it and say only that: said here, in the unit typed, and why.
        said = (lambda it, raw: _shown(it, raw, True)) if args.raw else \
            (lambda it, raw: units.show_as_typed(it, args.value, raw))
        if why := s.out_of_order(item, value, said):
            raise NotSent(f"servo {args.id}: {item.name} = {said(item, value)} not sent: {why}")
        s.write(item.id, value)
        print(f"{item.name} = {_shown(item, value, args.raw)}")
        link_rate.after_set(bus, args, item.name, value)
    elif args.action == "dump":
        values = config_file.settable(s)
        if args.json:
            print(json.dumps(values if args.raw else config_file.config_json(values, config_file.servo_of(s))))
        else:
            _print_config(values, args.raw)
    elif args.action == "save":
        print(config_file.save(args.file, s))
    elif args.action == "load":
        entry = config_file.parse_config(config_file.read(args.file), args.file, args.raw)
        serial, baud = s.read("serial"), s.read("baud")  # before: the load may move the servo
        other = entry.serial is not None and entry.serial != serial
        # A file not known to be this servo's (another's, or one with no serial: a raw
        # dump, a hand-written file) does not bring a zero, an amplifier offset, a
        # direction (gear_ratio's sign) or a drive train: they would move the angles and
        # limits, or run the loop the wrong way round.
        unknown = entry.serial != serial and not args.with_calibration
        own = [i.name for i in registers.DRIVE if i.name in entry.values] if unknown else []
        # Nor does it change a joint's range (this servo's narrowed limits), nor bring
        # another servo's, which is in that servo's zero.
        if unknown and (narrowed_limits(s) or (other and joint_range(entry.values))):
            own += [n for n in ("angle_limit_on", "angle_min", "angle_max") if n in entry.values]
        values = {k: v for k, v in entry.values.items() if k not in own}
        kept = group.write_user_area(s, values, args.with_link)  # validated before sending
        notes = link_rate.after_load(bus, args, s.id, baud, entry.values.get("baud", baud))
        notes += [f"kept {', '.join(f'{k} {s.read(k)}' for k in kept)}; --with-link to change"] if kept else []
        notes += [f"{n} in RAM: lost at power-up"] if (n := sum(i.name in entry.values for i in registers.RAM)) else []
        if entry.raw:
            notes.append("a raw file: protocol units")
        if other:
            notes.append(f"the file is servo serial 0x{entry.serial:08x}'s")
        if own:
            notes.append(f"{'its' if other else 'a file of no serial: its'} calibration, drive train and "
                         f"joint range not loaded ({', '.join(own)}); --with-calibration to load them")
        note = f" ({'; '.join(notes)})" if notes else ""
        print(f"loaded {len(values)} item(s) from {args.file} into servo {args.id}{note}")
    elif args.action == "reset":
        joint = narrowed_limits(s)
        s.reset_user_data()
        print(f"servo {args.id}: user area reset (ID and baud rate kept)")
        if joint is not None:  # said: the joint's range is gone with the rest
            print(f"servo {args.id}: its angle limits, {joint[0] / 10:.1f}..{joint[1] / 10:.1f} deg (a joint's range), "
                  "are the factory's +-135 deg again: set them again before it moves in its joint")
    return 0


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "store": cmd_store,
    "config": cmd_config,
}
