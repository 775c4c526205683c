"""`servoctl ui` on a simulated bus, and Debian's chromium driven by
Playwright (no browser download: /usr/bin/chromium, which scripts/setup.sh
installs), for the browser tests (test_ui.py) and for measuring the page
(scripts/ui_figures.py)."""
import os
import signal
import subprocess
import sys
import tempfile
import urllib.error
import urllib.request
from pathlib import Path

CHROMIUM = os.environ.get("SERVO_UI_CHROMIUM", "/usr/bin/chromium")
# What chromium needs on a closed network (docs/ui.md): no sandbox as root,
# no GPU, none of its own background connections.
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]
TOOLS = Path(__file__).resolve().parents[1]


class UiProcess:
    """servoctl --port BUS --sim-control PORT ui --no-browser, a child
    process; url is its first line's address."""

    def __init__(self, sim, extra=()):
        self.sim, self.extra = sim, list(extra)
        self.process, self.url, self.first_line = None, None, ""

    def __enter__(self):
        argv = [sys.executable, "-m", "servoctl.cli", "--port", self.sim.url, "--sim-control",
                str(self.sim.control_port), "ui", "--no-browser", *self.extra]
        self.process = subprocess.Popen(argv, cwd=TOOLS, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        text=True)
        self.first_line = self.process.stdout.readline().rstrip("\n")
        if not self.first_line.startswith("servoctl ui: http://"):
            err = self.stop()[1]
            raise RuntimeError(f"servoctl ui did not start: {self.first_line!r} {err}")
        self.url = self.first_line.split(" ", 2)[2]
        return self

    def stop(self, timeout_s: float = 10) -> tuple:
        """Ctrl-C (SIGINT), as a user stops it: (exit status, stderr)."""
        if self.process is None:
            return None, ""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        try:
            _, err = self.process.communicate(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self.process.kill()
            _, err = self.process.communicate()
        code, self.process = self.process.returncode, None
        return code, err

    def __exit__(self, *exc):
        self.stop()

    @property
    def base(self) -> str:
        return self.url.split("/?", 1)[0]

    @property
    def token(self) -> str:
        return self.url.split("token=", 1)[1]


def http_status(url: str, origin: str = None, host: str = None) -> int:
    """A GET's status, with the Origin and Host headers given."""
    req = urllib.request.Request(url, headers={**({"Origin": origin} if origin else {}),
                                               **({"Host": host} if host else {})})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status
    except urllib.error.HTTPError as e:
        return e.code


def launch_chromium(playwright):
    """Debian's chromium with a fresh profile; (browser, profile folder)."""
    profile = tempfile.mkdtemp(prefix="servo-ui-chromium-")
    context = playwright.chromium.launch_persistent_context(
        profile, executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS,
        viewport={"width": 1280, "height": 860}, accept_downloads=True)
    return context, profile


def navigation_ms(page) -> dict:
    """The page's Navigation Timing, ms from the request: DOM ready, loaded."""
    return page.evaluate("""() => { const n = performance.getEntriesByType('navigation')[0];
        return {dom_ready_ms: n.domContentLoadedEventEnd, load_ms: n.loadEventEnd}; }""")
