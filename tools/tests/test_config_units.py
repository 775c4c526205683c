"""Config and backup files write every item with its unit: the drive and
gain items (80-91) and the jerk limit too, which were bare numbers
("2741"); each reads back exactly, and a file written before (bare
numbers) still loads. No servo needed: the file's arithmetic."""
from servoctl import config_file, registers, units

OWN_UNIT = [i for i in registers.STORED + registers.RAM if i.unit and not i.quantity]


def _values():
    """A value within each item's range, not a round one."""
    return {i.name: min(max(i.low, 1234), i.high) for i in registers.STORED + registers.RAM}


def test_the_drive_items_are_written_with_their_units_and_read_back():
    values = _values()
    doc = config_file.config_json(values, {"id": 1})
    written = dict(doc["items"], **doc["ram_items"])
    assert {i.id for i in OWN_UNIT} >= set(range(80, 92)) - {82}  # 82, gear_ratio: a ratio, no unit
    for item in OWN_UNIT:
        assert written[item.name].endswith(item.unit), (item.name, written[item.name])
    assert written["motor_resistance"] == "1234 mOhm"
    assert written["coulomb_friction"] == "1234 x 0.1 uN m"  # a multiple of its unit, said so
    assert config_file.parse_config(doc, "c.json", raw_ok=False).values == values


def test_a_file_of_bare_drive_items_still_loads():
    values = _values()
    doc = config_file.config_json(values, {"id": 1})
    for item in OWN_UNIT:
        section = "ram_items" if item in registers.RAM else "items"
        doc[section][item.name] = str(values[item.name])  # as files were written before
    assert config_file.parse_config(doc, "old.json", raw_ok=False).values == values


def test_a_unit_that_is_not_the_items_own_is_refused():
    gain = registers.find("gain_kp")
    assert units.to_raw(gain, "546 Q15 duty/0.1deg") == units.to_raw(gain, "546") == 546
    for text in ("546 mOhm", "546.5"):
        try:
            units.to_raw(gain, text)
        except units.UsageError as e:
            assert "of Q15 duty/0.1deg" in str(e), e
        else:
            raise AssertionError(f"{text!r} was taken")
