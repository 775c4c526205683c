"""How many messages a tab may send (docs/ui.md, "A tab that floods"): the
page sends a few a second (a click, a jog every 200 ms at most); a tab
over RATE a second (BURST at once) has the rest refused, unparsed, but for
a STOP ALL, which is always taken; one that has sent CUT_AFTER over its
rate (STOP ALLs too) is cut off. Before, a burst of 20 000 small messages from one tab, each taken
without the server's loop turning once, held another tab's STOP ALL for up
to 2.5 s: the server now yields to its loop after each message
(server.Page.socket), and the cap bounds what a tab makes it do."""
import json
import time

RATE = 100       # messages a second a tab may send, sustained
BURST = 200      # and at once
CUT_AFTER = 2000  # messages over the rate; then the tab is cut off
NOTICE_S = 1.0   # host seconds: a refusal is said once in this, the others counted


class Pace:
    """One tab's token bucket, on the host's monotonic clock."""

    def __init__(self, clock=time.monotonic):
        self.clock = clock
        self.tokens = float(BURST)
        self.at = clock()
        self.refused = 0
        self.said_at = None  # when a refusal was last said to the tab

    def take(self) -> bool:
        """Whether this message is within the tab's rate (a token taken)."""
        now = self.clock()
        self.tokens = min(float(BURST), self.tokens + (now - self.at) * RATE)
        self.at = now
        if self.tokens >= 1.0:
            self.tokens -= 1.0
            return True
        return False

    def refuse(self) -> str:
        """Counts a message over the rate: the text to tell the tab, or
        None (said less than NOTICE_S ago)."""
        self.refused += 1
        now = self.clock()
        if self.said_at is not None and now - self.said_at < NOTICE_S:
            return None
        self.said_at = now
        return (f"servoctl ui: this tab sent over {RATE} messages a second: refused, not run ({self.refused} so "
                f"far; STOP ALL is still taken); a tab that keeps on is cut off after {CUT_AFTER}")

    def cut(self) -> bool:
        return self.refused >= CUT_AFTER

    def cut_text(self, who: str) -> str:
        return f"{who} is cut off: {self.refused} messages over the {RATE} a second a tab may send"


def is_stop(data) -> bool:
    """Whether a short message asks for STOP ALL (checked without a full
    parse's cost: at most 1 KiB, as a watching tab's)."""
    if len(data) > 1024:
        return False
    text = data if isinstance(data, str) else bytes(data).decode("utf-8", "replace")
    if "stopall" not in text:
        return False
    try:
        ask = json.loads(text)
    except (ValueError, RecursionError):
        return False
    return isinstance(ask, dict) and ask.get("op") == "stopall"
