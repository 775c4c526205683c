"""What the stream tests read from servoctl stream's report."""
import re


def lead_in_of(out: str):
    """servoctl stream's report of servo 1's lead-in: (from, to) in deg."""
    m = re.search(r"servo 1: from (-?[0-9.]+) deg to (-?[0-9.]+) deg", out)
    assert m, out
    return float(m.group(1)), float(m.group(2))
