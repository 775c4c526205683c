import pytest

from servoctl import ntc


def test_reference_points():
    assert ntc.celsius_to_adc(25.0) == 2048
    assert ntc.adc_to_celsius(2048) == pytest.approx(25.0, abs=0.05)
    # docs/protocol.md: 651 is about 75 degC.
    assert 74.0 < ntc.adc_to_celsius(651) < 77.0


def test_round_trip_and_direction():
    previous = None
    for c in range(-40, 151, 5):
        adc = ntc.celsius_to_adc(c)
        assert ntc.adc_to_celsius(adc) == pytest.approx(c, abs=0.5)
        if previous is not None:
            assert adc < previous  # the ADC value falls as it heats
        previous = adc


def test_firmware_table_agrees(tmp_path):
    """The table the firmware is built with comes from the same relation."""
    import re
    import subprocess
    import sys
    from pathlib import Path

    gen = Path(__file__).resolve().parents[2] / "services" / "sensors" / "gen_ntc_table.py"
    out = tmp_path / "ntc_table.c"
    subprocess.run([sys.executable, str(gen), str(out)], check=True)
    rows = re.findall(r"^\s+(\d+), /\* (-?\d+) degC \*/", out.read_text(), re.M)
    assert len(rows) == 39
    for adc, celsius in rows:
        assert int(adc) == ntc.celsius_to_adc(int(celsius))


@pytest.mark.parametrize("bad", [0, 4096, -3])
def test_out_of_range_is_refused(bad):
    with pytest.raises(ValueError, match="outside"):
        ntc.adc_to_celsius(bad)
