"""servoctl's check of drive and gain items (stability.py), without a servo:
the servo's own rules as the firmware works them out (drive_items_stable,
mirrored in the same integer arithmetic: tests/unit/test_oscillation.c has
the same cases), tune's margins, and the order of writes."""
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


def test_write_order_keeps_each_step_stable_and_refuses_a_bad_end():
    for target in PLANTS.values():
        state = dict(FACTORY)
        changes = {k: v for k, v in target.items() if FACTORY[k] != v}
        for name in stability.write_order(FACTORY, changes):
            was_stable = stability.firmware_reason(state) is None
            state[name] = target[name]
            assert not was_stable or stability.firmware_reason(state) is None, name
        assert state == target
    with pytest.raises(ValueOutOfRange, match="torque_constant = 37140 refused, not written"):
        stability.write_order(FACTORY, {"torque_constant": 37140})
