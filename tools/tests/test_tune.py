"""servoctl tune's arithmetic, without a servo: the gains place the closed
loop's poles where asked, the drive train goes to the items at the motor,
and what cannot be done is refused with the reason."""
import math

import numpy as np
import pytest

from servoctl.errors import ServoError
from servoctl.identify import DriveTrain, Estimate
from servoctl.tune import _plant, _si, drive_items, gains_for, margins, range_limit_hz, tune

# The reference plant at the output (hal/ports/host/plants/reference_st3215.toml).
REFERENCE = DriveTrain(torque_constant=Estimate(3.714e-3 * 345, 0), resistance=Estimate(2.741, 0),
                       inertia=Estimate(1.0e-7 * 345 ** 2, 0), coulomb=Estimate(2.786e-4 * 345, 0),
                       viscous=Estimate(1.481e-7 * 345 ** 2, 0), supply_v=7.4, steps_used=8)


@pytest.mark.parametrize("hz", [2.0, 5.0, 8.0])
def test_the_gains_put_the_poles_where_asked(hz):
    g, d, j = _plant(REFERENCE)
    kp, _, kd = _si(*gains_for(REFERENCE, hz, zeta=0.7))
    poles = np.roots([j, d + g * kd, g * kp])  # J s^2 + (D + G kd) s + G kp
    wn = math.sqrt(abs(poles[0] * poles[1]))
    zeta = -(poles[0] + poles[1]).real / (2 * wn)
    assert wn == pytest.approx(2 * math.pi * hz, rel=1e-9)
    if kd > 0:
        assert zeta == pytest.approx(0.7, rel=1e-9)
    else:  # the back-EMF alone damps more than asked (2 and 5 Hz here): no kd
        assert zeta > 0.7


def test_the_reference_drive_train_gives_the_factory_items():
    items = drive_items(REFERENCE, 345)
    assert items == {"motor_resistance": 2741, "torque_constant": 3714, "rotor_inertia": 1000,
                     "coulomb_friction": 2786, "viscous_friction": 1481}


def test_the_default_bandwidth_and_its_margins():
    t = tune(REFERENCE, 345)
    assert t.bandwidth_hz == 8.0 and range_limit_hz(REFERENCE) > 10.0
    assert 40 <= t.phase_margin_deg <= 70 and t.gain_margin_db > 20
    assert 450 <= t.kp <= 550 and t.ki >= 1  # the factory's 546 are 8.4 Hz
    assert 0.5 * t.bandwidth_hz < t.crossover_hz < 1.5 * t.bandwidth_hz


def test_a_longer_delay_costs_phase_margin(monkeypatch):
    """The margins see the loop's delay: 3.5 ms more of it costs the phase
    margin 360 fc x 3.5 ms degrees at the crossover fc."""
    from servoctl import loop_model as module  # tune.margins is its

    gains = gains_for(REFERENCE, 8.0)
    pm, _, fc = margins(REFERENCE, *gains)
    monkeypatch.setattr(module, "DELAY_S", module.DELAY_S + 0.0035)
    slower, _, _ = margins(REFERENCE, *gains)
    assert slower == pytest.approx(pm - 360.0 * fc * 0.0035, abs=0.05)


def test_a_reversed_ratio_gives_the_same_items():
    """Calibrate's sign on item 82 is the direction: the magnitudes are the ratio."""
    assert drive_items(REFERENCE, -345) == drive_items(REFERENCE, 345)


def test_what_cannot_be_done_is_refused_with_the_reason():
    with pytest.raises(ServoError, match=r"at most \d+\.\d+ Hz"):
        tune(REFERENCE, 345, bandwidth_hz=100.0)
    with pytest.raises(ServoError, match="set gear_ratio"):
        drive_items(REFERENCE, 1)  # the inertia at the motor would be 119 000 mg cm^2: beyond item 83
    with pytest.raises(ServoError, match="gear_ratio is 0"):
        drive_items(REFERENCE, 0)
