"""A tab's request fields (servoctl.ui.fields): a field of the wrong type
is malformed, never taken for another value. "false" ran a scan of every
baud rate; a mode of [1] or {"x": 1} meant release without a word."""
import pytest

from servoctl.ui.fields import Malformed, flag, mode


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
