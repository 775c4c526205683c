"""Drive and gain items (80-88) that would make the closed loop unstable are
refused before they are written (docs/safety.md, "Drive items the loop
refuses"): the servo's own rules, as its firmware works them out
(motion/controller.c, drive_items_stable), and the margins tune gives, of
the loop the items declare.

The plant the items declare, at the output: K = kt |ratio|, R, J = J_motor
ratio^2, B = viscous ratio^2, at the nominal supply (7.4 V); the gains are
items 86-88. A set is refused where

  - the servo's own rules fail (the same integer arithmetic): kv, the
    back-EMF duty of 0.1 deg per tick, clamped by its fixed point (the
    output's no-load speed below 50 deg/s at 7.4 V); ka < kv (the motor's
    mechanical time constant below the 1 ms tick); the PID loop on the
    declared plant short of twice Hurwitz's bound, (kv + viscous + kd) kp
    >= 2 ka ki;
  - or tune's model (loop_model.margins, tune's, the 1.5 ticks of delay included) gives a
    phase margin below MIN_PHASE_MARGIN_DEG or a gain margin below
    MIN_GAIN_MARGIN_DB.

Ratio 0 declares no plant (no feed-forward): nothing to judge. Items are
written one at a time, each kept: write_order finds an order in which each
set along the way passes too, by way of gain_ki 0 where no plain order
does."""
import math
from types import SimpleNamespace

from . import registers
from .errors import ValueOutOfRange
from .loop_model import margins

NOMINAL_SUPPLY_MV = 7400
MIN_PHASE_MARGIN_DEG = 20.0
MIN_GAIN_MARGIN_DB = 6.0
ITEMS = ("motor_resistance", "torque_constant", "gear_ratio", "rotor_inertia", "coulomb_friction",
         "viscous_friction", "gain_kp", "gain_ki", "gain_kd")

# controller.c's scales and bounds.
KV_SCALE_Q6, KA_SCALE, FRICTION_SCALE, VISCOUS_SCALE_Q5 = 3660, 5719, 3277, 183
DERIVED_MAX, KA_MAX = 65535, 1 << 30


def _derived(a: int, b: int, den: int, most: int) -> int:
    return min(a * b // den, most)


def derived(v: dict, supply_mv: int = NOMINAL_SUPPLY_MV) -> dict:
    """kv, ka and viscous as drive_limits_for_supply works them out."""
    r, kt, ratio = v["motor_resistance"], v["torque_constant"], abs(v["gear_ratio"])
    per_torque = kt * supply_mv
    return {"kv": _derived(kt * ratio, KV_SCALE_Q6, supply_mv << 6, DERIVED_MAX),
            "ka": _derived(v["rotor_inertia"] * ratio, r * KA_SCALE, per_torque, KA_MAX) | 1,
            "viscous": _derived(v["viscous_friction"] * ratio, (r * VISCOUS_SCALE_Q5) >> 5, per_torque,
                                DERIVED_MAX)}


def firmware_reason(v: dict):
    """Why the servo's own check (drive_items_stable) refuses v, or None."""
    if v["gear_ratio"] == 0:
        return None
    d = derived(v)
    if d["kv"] >= DERIVED_MAX:
        return ("torque_constant x gear_ratio gives an output no-load speed below 50 deg/s at 7.4 V "
                "(the back-EMF feed-forward would be clamped)")
    if d["ka"] < d["kv"]:
        return ("rotor_inertia x motor_resistance / torque_constant^2 gives a mechanical time constant "
                "below the 1 ms control tick")
    damping = d["kv"] + d["viscous"] + v["gain_kd"]
    if (d["ka"] >> 10) * v["gain_ki"] > (damping * v["gain_kp"]) >> 11:
        return "gain_ki is too high for gain_kp and gain_kd on this drive train (the integral would swing)"
    return None


def declared_drive(v: dict):
    """The plant the items declare, at the output, in tune's terms."""
    n = abs(v["gear_ratio"])
    q = lambda x: SimpleNamespace(value=x)  # noqa: E731
    return SimpleNamespace(torque_constant=q(v["torque_constant"] * 1e-6 * n),
                           resistance=q(v["motor_resistance"] * 1e-3),
                           inertia=q(v["rotor_inertia"] * 1e-10 * n * n),
                           viscous=q(v["viscous_friction"] * 1e-10 * n * n),
                           coulomb=q(v["coulomb_friction"] * 1e-7 * n),
                           supply_v=NOMINAL_SUPPLY_MV / 1000.0)


def reason(v: dict):
    """Why the set of items v (by name, 80-88) would make the loop unstable,
    or None."""
    why = firmware_reason(v)
    if why or v["gear_ratio"] == 0:
        return why
    pm, gm, _ = margins(declared_drive(v), v["gain_kp"], v["gain_ki"], v["gain_kd"])
    pm = (pm + 180.0) % 360.0 - 180.0  # an unwrapped phase can pass -180 deg and read 355
    if math.isnan(pm) or pm < MIN_PHASE_MARGIN_DEG or gm < MIN_GAIN_MARGIN_DB:
        return (f"the loop these items declare has a phase margin of {pm:.0f} deg and a gain margin of "
                f"{gm:.1f} dB (at least {MIN_PHASE_MARGIN_DEG:g} deg and {MIN_GAIN_MARGIN_DB:g} dB)")
    return None


def _search(now: dict, pending: dict):
    """A depth-first search over the orders of writing pending (name:
    value) from now, each write judged as the servo judges it (refused
    where it takes a passing set to a failing one; a set already failing
    takes any). The (name, value) writes in order, or None and the deepest
    refusal met: (the items written before, the item, why)."""
    dead, blocked = set(), [(), None, None]

    def go(state: dict, done: tuple):
        left = [n for n in pending if n not in done]
        if not left:
            return []
        if frozenset(done) in dead:
            return None
        was_failing = firmware_reason(state) is not None
        for name in left:
            trial = dict(state, **{name: pending[name]})
            why = firmware_reason(trial)
            if why is None or was_failing:
                rest = go(trial, done + (name,))
                if rest is not None:
                    return [(name, pending[name])] + rest
            elif blocked[1] is None or len(done) >= len(blocked[0]):
                blocked[:] = [done, name, why]
        dead.add(frozenset(done))
        return None

    return go(dict(now), ()), tuple(blocked)


def write_order(now: dict, changes: dict) -> list:
    """The writes, (name, value), that take the servo from now to now with
    changes (name: value), in an order where each set along the way passes
    the servo's own check (each write is kept, so each is judged); refused,
    naming why, where the final set fails or no order passes.

    Rule 3 (ki) is not monotone in the drive items: kt raises kv and lowers
    ka but also the viscous term; the ratio raises ka and kv both. So two
    tuned servos' sets can have no plain order (a micro servo's items to a
    60 kg cm servo's). Then gain_ki is written 0 first (rule 3 then holds
    whatever the rest; rules 1-2 do not read ki), the others in an order
    that passes rules 1-2, and gain_ki last. With ki 0 an order always
    exists but for the integer rounding: rules 1-2 are monotone in kt, J, R
    and |ratio| (kt x |ratio| < bound; J R / kt^2 >= bound), so the items
    that ease them first, then those that tighten them, each set as eased
    as the final one; the search finds it, or names the intermediate set's
    failing rule. The ki 0 sets last a write each: the loop runs PD there,
    which the rules judge stable."""
    final = dict(now, **changes)
    why = reason(final)
    if why:
        factory = ", ".join(f"{k} {registers.find(k).default}" for k in changes)
        raise ValueOutOfRange(f"{', '.join(f'{k} = {v}' for k, v in changes.items())} refused, not written: "
                              f"{why} (factory: {factory}); nothing was sent")
    order, blocked = _search(now, changes)
    if order is None and now["gain_ki"] != 0:
        rest = {k: v for k, v in changes.items() if k != "gain_ki"}
        # ki 0 from now is kept: rule 3 holds with ki 0, rules 1-2 are now's.
        via, blocked = _search(dict(now, gain_ki=0), rest)
        if via is not None:
            order = [("gain_ki", 0)] + via + ([("gain_ki", final["gain_ki"])] if final["gain_ki"] else [])
    if order is None:
        done, name, why = blocked
        after = f"after {', '.join(done)}" if done else "first"
        raise ValueOutOfRange(f"no order of writing {', '.join(changes)} keeps the servo's loop stable at each step "
                              f"(gain_ki 0 first included): {name} written {after} would be refused: {why}")
    return order


def is_drive_item(key) -> bool:
    return registers.find(key).name in ITEMS
