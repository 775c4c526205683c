"""The NTC relation of docs/protocol.md, "The temperature reading", both ways, for tools.

The status area reports temperature as the ADC value of an NTC divider
(10 kohm to the rail, 10 kohm NTC with B = 3435 to ground, 12-bit ADC), so the
value falls as the servo heats: about 2048 at 25 degC, 651 at about 75 degC.
The firmware converts with a table generated from the same formula
(services/sensors/gen_ntc_table.py); tools use the formula itself.
"""
from decimal import Decimal, localcontext

R1 = Decimal(10000)
R25 = Decimal(10000)
B = Decimal(3435)
K = Decimal("273.15")
FULL_SCALE = 4096
# Decimal's exp and ln are correctly rounded in software: a value written to
# the servo (a temperature limit) is the same on every machine, where libm's
# exp may differ in its last bit with the CPU (docs/testing.md, "On any machine").
DIGITS = 34


def adc_to_celsius(adc: float) -> float:
    """Temperature in degC for an ADC value (1..4095)."""
    if not 0 < adc < FULL_SCALE:
        raise ValueError(f"NTC ADC value {adc} is outside 1..{FULL_SCALE - 1}")
    with localcontext() as ctx:
        ctx.prec = DIGITS
        rt = R1 * Decimal(adc) / (FULL_SCALE - Decimal(adc))
        return float(1 / ((rt / R25).ln() / B + 1 / (K + 25)) - K)


def celsius_to_adc(celsius: float) -> int:
    """The ADC value the servo reports at a temperature in degC."""
    if celsius != celsius:
        raise ValueError("NaN is not a temperature")
    if celsius <= -273.15:
        raise ValueError(f"{celsius} degC is below absolute zero")
    with localcontext() as ctx:
        ctx.prec = DIGITS
        rt = R25 * (B * (1 / (K + Decimal(celsius)) - 1 / (K + 25))).exp()
        return int((rt * FULL_SCALE / (rt + R1)).to_integral_value())  # half to even, as round()


def celsius_or_none(adc: int, places: int = 1):
    """degC rounded to places, or None for a reading no NTC gives (0, 4095 and
    beyond: no sensor, or a short)."""
    try:
        return round(adc_to_celsius(adc), places)
    except ValueError:
        return None


def describe(adc: int) -> str:
    """A temperature reading for people: degC with the ADC value it came from."""
    celsius = celsius_or_none(adc)
    return f"{celsius:.1f} degC (ADC {adc})" if celsius is not None else f"ADC {adc} (no sensor?)"
