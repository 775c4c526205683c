"""move --wait names soft start only where it can explain the time taken:
it stretches the first move to soft_start_time, no further."""
from servoctl.outcome import Plan, planned_text


def _plan(planned_s, soft_s):
    return Plan(0, 0, 0, 0, False, planned_s, soft_s)


def test_soft_start_is_blamed_only_for_a_move_it_could_have_stretched():
    plan = _plan(0.5, 3.0)
    assert "soft start is on (3000 ms" in planned_text(plan, 3.05)  # a first move, stretched
    # A move that cannot arrive (too fast for the motor) outlasts any soft start.
    assert planned_text(plan, 2 * 0.5 + 3.0 + 2.0) == "planned 500 ms"
    assert planned_text(_plan(0.5, 0.0), 3.05) == "planned 500 ms"  # soft start off
