"""servoctl's number checks (servoctl.checks): a value in a person's
units to the protocol's, or a range error that says what was given."""
import pytest

from servoctl.checks import scaled
from servoctl.errors import ValueOutOfRange


def test_a_finite_number_past_every_range_says_so():
    """1e308 degrees is finite, and 1e308 x 10 is not: a move said
    "cannot convert float infinity to integer"."""
    with pytest.raises(ValueOutOfRange, match=r"angle 1e\+308 is beyond any range it takes"):
        scaled(1e308, 10, "angle")
    with pytest.raises(ValueOutOfRange, match="angle takes a finite number, not nan"):
        scaled(float("nan"), 10, "angle")
    assert scaled(-12.34, 10, "angle") == -123


def test_the_move_command_says_a_range_not_an_overflow(capsys):
    from servoctl.cli import main
    assert main(["--port", "loop://", "move", "1", "1e308", "--multi-turn"]) == 2
    err = capsys.readouterr().err
    assert "beyond any range" in err and "Traceback" not in err and "infinity" not in err, err
