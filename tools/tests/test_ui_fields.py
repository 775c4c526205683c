"""A tab's request fields (servoctl.ui.fields): a field of the wrong type
is malformed, never taken for another value. "false" ran a scan of every
baud rate; a mode of [1] or {"x": 1} meant release without a word."""
import pytest

from servoctl.ui.fields import Malformed, flag, mode, servo_id


def test_a_flag_is_true_or_false_only():
    assert flag(True, "all_bauds") is True and flag(False, "all_bauds") is False
    for wrong in ("false", "true", 0, 1, [0], {"x": 1}, None):
        with pytest.raises(Malformed, match="all_bauds must be true or false"):
            flag(wrong, "all_bauds")


def test_a_stop_mode_is_release_or_damping_only():
    assert mode(None) == "release" and mode("release") == "release" and mode("damping") == "damping"
    for wrong in ([1], {"x": 1}, "hold", "", 1, True):
        with pytest.raises(Malformed, match="mode must be 'release' or 'damping'"):
            mode(wrong)


def test_a_servo_id_out_of_range_is_malformed_here():
    """{"op": "items", "id": 1000, "tag": 0} was refused on the bus thread,
    whose answer had lost the tag: the page could not show it by the request."""
    assert servo_id(0, "id") == 0 and servo_id("254", "id") == 254
    for wrong in (255, 1000, -1):
        with pytest.raises(Malformed, match="a servo ID is 0..254"):
            servo_id(wrong, "id")
