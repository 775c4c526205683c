"""servoctl's check of drive and gain items (stability.py), without a servo:
the servo's own rules as the firmware works them out (drive_items_stable,
mirrored in the same integer arithmetic: tests/unit/test_oscillation.c has
the same cases), tune's margins, and the order of writes."""
import math
import random
from unittest.mock import patch

import pytest

from servoctl import registers, stability
from servoctl.errors import ValueOutOfRange

FACTORY = {i.name: i.default for i in registers.DRIVE if i.name in stability.ITEMS}
# The shipped plants' items as tune gives them at 8 Hz (tests/unit/test_oscillation.c's).
PLANTS = {
    "reference": dict(FACTORY, gain_kp=497, gain_ki=6, gain_kd=3654),
    "micro": {"motor_resistance": 6400, "torque_constant": 1324, "gear_ratio": 300, "rotor_inertia": 51,
              "coulomb_friction": 662, "viscous_friction": 211, "gain_kp": 223, "gain_ki": 3, "gain_kd": 1104},
    "60kgcm": {"motor_resistance": 2400, "torque_constant": 5063, "gear_ratio": 387, "rotor_inertia": 12570,
               "coulomb_friction": 6330, "viscous_friction": 2811, "gain_kp": 533, "gain_ki": 3,
               "gain_kd": 24297},
}


def test_the_factory_items_and_the_shipped_plants_pass():
    assert stability.reason(FACTORY) is None
    for items in PLANTS.values():
        assert stability.reason(items) is None


@pytest.mark.parametrize("name,value,why", [
    ("torque_constant", 37140, "no-load speed below 50 deg/s"),
    ("gear_ratio", 3450, "no-load speed below 50 deg/s"),
    ("gear_ratio", 32767, "no-load speed below 50 deg/s"),
    ("torque_constant", 65535, "no-load speed below 50 deg/s"),
    ("gear_ratio", -3450, "no-load speed below 50 deg/s"),
    ("rotor_inertia", 1, "mechanical time constant below the 1 ms"),
    ("gain_ki", 80, "gain_ki is too high"),
])
def test_the_servos_own_rules(name, value, why):
    assert why in stability.firmware_reason(dict(FACTORY, **{name: value}))


def test_the_margins_catch_what_the_servos_rules_let_by():
    """The micro-servo's drive train with kd at its most: the servo's own
    rules (no delay in them) let it by; tune's model, with the 1.5 ticks
    of delay, gives it a gain margin of 5.4 dB."""
    items = dict(PLANTS["micro"], gain_kp=1023, gain_kd=32767)
    assert stability.firmware_reason(items) is None
    assert "gain margin of 5.4 dB" in stability.reason(items)


def test_ratio_zero_declares_no_plant():
    assert stability.reason(dict(FACTORY, gear_ratio=0, gain_ki=1023)) is None


def test_derived_as_the_firmware():
    """kv, ka and viscous of the factory items at 7.4 V: test_servo.c's and
    controller.c's figures."""
    assert stability.derived(FACTORY) == {"kv": 9902, "ka": 196777, "viscous": 291}


def _walk(now: dict, target: dict) -> dict:
    """The writes write_order gives from now to target, each judged as the
    servo judges it (a passing set must stay passing); the set at the end."""
    state = dict(now)
    for name, value in stability.write_order(now, {k: v for k, v in target.items() if now[k] != v}):
        was_stable = stability.firmware_reason(state) is None
        state[name] = value
        assert not was_stable or stability.firmware_reason(state) is None, (name, value)
    return state


def test_write_order_keeps_each_step_stable_and_refuses_a_bad_end():
    for target in PLANTS.values():
        assert _walk(FACTORY, target) == target
    with pytest.raises(ValueOutOfRange, match="torque_constant = 37140 refused, not written"):
        stability.write_order(FACTORY, {"torque_constant": 37140})


@pytest.mark.parametrize("start,end", [("micro", "60kgcm"), ("60kgcm", "micro")])
def test_write_order_between_the_tuned_plants_goes_by_way_of_ki_zero(start, end):
    """One shipped plant's tuned items onto the other's (config load): no
    plain order passes rule 3 at each step (was refused, "...: None"); with
    gain_ki 0 first, the rest, then gain_ki, each step passes."""
    order = stability.write_order(PLANTS[start], {k: v for k, v in PLANTS[end].items()
                                                  if PLANTS[start][k] != v})
    assert order[0] == ("gain_ki", 0) and order[-1] == ("gain_ki", PLANTS[end]["gain_ki"])
    assert _walk(PLANTS[start], PLANTS[end]) == PLANTS[end]


def test_write_order_finds_a_path_between_any_two_passing_sets():
    """Random passing sets (the servo's rules; tune's margins aside): rules
    1-2 are monotone in kt, J, R and |ratio|, so with ki 0 an order exists."""
    rng = random.Random(55)
    bounds = {"motor_resistance": (500, 20000), "torque_constant": (500, 20000), "gear_ratio": (-600, 600),
              "rotor_inertia": (10, 50000), "coulomb_friction": (0, 10000), "viscous_friction": (0, 10000),
              "gain_kp": (1, 1023), "gain_ki": (0, 60), "gain_kd": (0, 32767)}

    def passing():
        while True:
            v = {k: rng.randint(*b) for k, b in bounds.items()}
            if v["gear_ratio"] and stability.firmware_reason(v) is None:
                return v
    for _ in range(300):
        now, target = passing(), passing()
        with patch.object(stability, "reason", stability.firmware_reason):
            assert _walk(now, target) == target


def test_no_order_names_the_rule_an_intermediate_set_fails():
    """Where no order passes (a toy rule: kp and kd may not both be above
    100, nor both at most 100), the refusal names the step and its rule,
    never "None"."""
    def toy(v):
        return None if (v["gain_kp"] > 100) != (v["gain_kd"] > 100) else "toy rule: kp and kd on one side"
    now = dict(FACTORY, gain_kp=50, gain_kd=200)
    with patch.object(stability, "firmware_reason", toy), patch.object(stability, "reason", toy):
        with pytest.raises(ValueOutOfRange) as e:
            stability.write_order(now, {"gain_kp": 200, "gain_kd": 50})
    assert str(e.value).endswith("gain_kd written first would be refused: toy rule: kp and kd on one side")
    assert not str(e.value).endswith("None")


def _numpy_margins(drive, kp, ki, kd):
    """The margins as numpy's arrays gave them before loop_model.margins
    went to plain Python (the library needs only pyserial): the reference."""
    np = pytest.importorskip("numpy")
    from servoctl.loop_model import DELAY_S, _plant, _si
    g, d, j = _plant(drive)
    kp_si, ki_si, kd_si = _si(kp, ki, kd)
    w = np.logspace(-1, 4.5, 20000)
    s = 1j * w
    loop = (kp_si + kd_si * s + ki_si / s) * g / (s * (j * s + d)) * np.exp(-s * DELAY_S)
    mag, phase_deg = np.abs(loop), np.degrees(np.unwrap(np.angle(loop)))
    below = np.nonzero(mag < 1.0)[0]
    if below.size == 0:
        return math.nan, math.nan, math.nan
    c = below[0]
    after = np.nonzero(phase_deg[c:] <= -180.0)[0]
    gm = -20.0 * math.log10(mag[c + after[0]]) if after.size else math.inf
    return 180.0 + phase_deg[c], gm, w[c] / (2.0 * math.pi)


def _same(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or a == b or abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))


def test_the_plain_python_margins_are_numpys():
    """loop_model.margins point for point as numpy's logspace, unwrap and
    arrays gave them: on the shipped plants, the cases above and 400
    random sets of items (with kd, ki or kp 0 among them), the three
    figures equal to 1e-9, and every set judged alike."""
    np = pytest.importorskip("numpy")
    from servoctl.loop_model import frequencies, margins
    # numpy's power and the C library's differ in the last bit at some points
    assert np.allclose(np.array(frequencies()), np.logspace(-1, 4.5, 20000), rtol=4.5e-16, atol=0)
    rng = random.Random(80)
    sets = [*PLANTS.values(), FACTORY, dict(PLANTS["micro"], gain_kp=1023, gain_kd=32767)]
    sets += [dict(FACTORY, **{name: value}) for name, value, _ in [
        ("gain_kd", 0, ""), ("gain_ki", 0, ""), ("gain_kp", 1, ""), ("gain_kp", 1023, ""), ("gain_kd", 32767, "")]]
    while len(sets) < 410:
        v = {"motor_resistance": rng.randint(100, 65535), "torque_constant": rng.randint(100, 65535),
             "gear_ratio": rng.choice([1, -1]) * rng.randint(1, 3000), "rotor_inertia": rng.randint(1, 65535),
             "coulomb_friction": rng.randint(0, 65535), "viscous_friction": rng.randint(0, 65535),
             "gain_kp": rng.randint(0, 1023), "gain_ki": rng.choice([0, rng.randint(0, 1023)]),
             "gain_kd": rng.choice([0, rng.randint(0, 32767)])}
        sets.append(v)
    judged = set()
    for v in sets:
        drive = stability.declared_drive(v)
        ours, theirs = margins(drive, v["gain_kp"], v["gain_ki"], v["gain_kd"]), \
            _numpy_margins(drive, v["gain_kp"], v["gain_ki"], v["gain_kd"])
        assert all(_same(a, b) for a, b in zip(ours, theirs)), (v, ours, theirs)
        if stability.firmware_reason(v) is None:
            judged.add(stability.reason(v) is None)
    assert judged == {True, False}  # passing and refused sets both met
