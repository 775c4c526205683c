"""The NTC relation of docs/protocol.md, "The temperature reading", both ways, for tools.

The status area reports temperature as the ADC value of an NTC divider
(10 kohm to the rail, 10 kohm NTC with B = 3435 to ground, 12-bit ADC), so the
value falls as the servo heats: about 2048 at 25 degC, 651 at about 75 degC.
The firmware converts with a table generated from the same formula
(firmware/sensors/gen_ntc_table.py); tools use the formula itself.
"""
import math

R1 = 10000.0
R25 = 10000.0
B = 3435.0
K = 273.15
FULL_SCALE = 4096


def adc_to_celsius(adc: float) -> float:
    """Temperature in degC for an ADC value (1..4095)."""
    if not 0 < adc < FULL_SCALE:
        raise ValueError(f"NTC ADC value {adc} is outside 1..{FULL_SCALE - 1}")
    rt = R1 * adc / (FULL_SCALE - adc)
    return 1.0 / (math.log(rt / R25) / B + 1.0 / (K + 25.0)) - K


def celsius_to_adc(celsius: float) -> int:
    """The ADC value the servo reports at a temperature in degC."""
    if celsius <= -K:
        raise ValueError(f"{celsius} degC is below absolute zero")
    rt = R25 * math.exp(B * (1.0 / (K + celsius) - 1.0 / (K + 25.0)))
    return round(rt * FULL_SCALE / (rt + R1))


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
