"""servoctl ui's Motion view starts from where the servo is, in Debian's
chromium driven by Playwright against servo_sim (one servo resting at
60 deg): the jog slider stands at the servo's angle, a key press nudges it
one degree from there, and a jog far from it is refused with the slider put
back. The Servo view says an item refused for its pair's order in the unit
typed, and why. The horn is judged on the simulator's state."""
import shutil
import threading
from pathlib import Path

import pytest

from servoctl.servo import Servo
from servoctl.sim import Simulator
from ..ui_launch import CHROMIUM, UiProcess, launch_chromium

playwright_api = pytest.importorskip("playwright.sync_api")
WAIT_MS = 30000  # host time for the page to show what the bus thread did (a bound: on failure)
REST_DEG = 60.0


def rest_servo_1(sim) -> None:
    """Servo 1 at REST_DEG, soft start off, before the ui opens the bus."""
    with sim.bus() as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.move_to(REST_DEG, speed_dps=200, wait=True)


@pytest.fixture(scope="module")
def bench():
    if not Path(CHROMIUM).exists():
        pytest.fail(f"no {CHROMIUM}: scripts/setup.sh installs Debian's chromium")
    with Simulator(ids=[1]) as sim:
        rest_servo_1(sim)
        with playwright_api.sync_playwright() as pw, UiProcess(sim) as ui:
            context, profile = launch_chromium(pw)
            try:
                page = context.new_page()
                page.goto(ui.url)
                page.locator("#bus-table tr[data-id='1'] td.state", has_text="answering").wait_for(timeout=WAIT_MS)
                yield sim, page
            finally:
                context.close()
                shutil.rmtree(profile, ignore_errors=True)


class _Watch:
    """Servo 1's angles while it runs (seen), on the simulator's state."""

    def __init__(self, sim):
        self.sim, self.seen, self.done = sim, [], threading.Event()
        self.thread = threading.Thread(target=self._watch, daemon=True)

    def _watch(self):
        while not self.done.is_set():
            self.seen.append(self.sim.state(1)["angle"])
            self.done.wait(0.01)

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.done.set()
        self.thread.join()


def test_the_jog_slider_starts_at_the_servos_angle_and_nudges_from_there(bench):
    """It stood at 0 deg whatever the servo's angle: one ArrowRight sent
    "move 1 1 --interval 200" and threw the horn from 60 deg to 1 deg at
    full speed."""
    sim, page = bench
    page.click("#tabs button[data-view=motion]")
    page.wait_for_function(f"!document.querySelector('#jog').disabled"
                           f" && document.querySelector('#jog').value === '{REST_DEG:g}'", timeout=WAIT_MS)
    assert page.inner_text("#jog-at") == f"{REST_DEG:.1f} deg"
    with _Watch(sim) as watch:
        page.focus("#jog")
        page.keyboard.press("ArrowRight")
        page.locator("#motion-out", has_text="servo 1: at 61").wait_for(timeout=WAIT_MS)
    assert REST_DEG - 0.5 < min(watch.seen) and max(watch.seen) < REST_DEG + 1.5, (min(watch.seen), max(watch.seen))
    assert abs(sim.state(1)["angle"] - (REST_DEG + 1)) < 0.5
    page.wait_for_function("document.querySelector('#jog').value === '61'", timeout=WAIT_MS)


def test_a_jog_far_from_the_servo_is_refused_and_the_slider_put_back(bench):
    """The server takes a jog only a slider's step from the angle it reads
    (a slider clicked far off, or a page that did not hear a move)."""
    sim, page = bench
    at = sim.state(1)["angle"]
    page.evaluate("() => { const j = document.querySelector('#jog'); j.value = '1';"
                  " j.dispatchEvent(new Event('input')); }")
    page.locator("#motion-out", has_text="a jog moves 1.5 deg at most from where the servo is").wait_for(
        timeout=WAIT_MS)
    page.wait_for_function(f"document.querySelector('#jog').value === '{round(at)}'", timeout=WAIT_MS)
    assert abs(sim.state(1)["angle"] - at) < 0.5


def test_stop_all_drops_a_jog_the_slider_kept(bench):
    """The slider keeps its newest angle while a jog is under way and sent
    it when that jog came back, even stopped (130): after STOP ALL the servo
    moved again."""
    sim, page = bench
    page.click("#tabs button[data-view=motion]")
    at = round(sim.state(1)["angle"])
    page.wait_for_function(f"!document.querySelector('#jog').disabled"
                           f" && document.querySelector('#jog').value === '{at}'", timeout=WAIT_MS)
    page.evaluate(f"""() => {{ const j = document.querySelector('#jog');
        j.value = '{at + 1}'; j.dispatchEvent(new Event('input'));
        j.value = '{at + 1}'; j.dispatchEvent(new Event('input'));
        document.querySelector('#stop-all').click(); }}""")
    page.locator("#log", has_text="stop-all:").wait_for(timeout=WAIT_MS)
    stopped = sim.state(1)["angle"]
    with _Watch(sim) as watch:
        sim.sleep(1.5)
    assert max(abs(a - stopped) for a in watch.seen) < 0.2, (stopped, min(watch.seen), max(watch.seen))


def test_another_tabs_stop_all_drops_a_jog_the_slider_kept(bench):
    """A watching tab's STOP ALL answers a jog still queued "not run", not
    exit 130, and the driving tab then sent the angle its slider kept: the
    servo moved, and held, after the stop (round-4 review)."""
    sim, page = bench
    page.click("#tabs button[data-view=motion]")
    at = round(sim.state(1)["angle"])
    page.wait_for_function(f"!document.querySelector('#jog').disabled"
                           f" && document.querySelector('#jog').value === '{at}'", timeout=WAIT_MS)
    other = page.context.new_page()
    try:
        other.goto(page.url)
        other.locator("#role", has_text="watching").wait_for(timeout=WAIT_MS)
        page.bring_to_front()
        # A job that holds the bus without moving the servo; two jogs behind it: one queued, one kept.
        page.evaluate(f"""() => {{ UI.run(["move", "1", "{at}", "--interval", "1500", "--wait"]);
            const j = document.querySelector('#jog');
            j.value = '{at + 1}'; j.dispatchEvent(new Event('input'));
            j.value = '{at + 1}'; j.dispatchEvent(new Event('input')); }}""")
        sim.sleep(0.3)
        other.click("#stop-all")
        page.locator("#log", has_text="stop-all:").wait_for(timeout=WAIT_MS)
        stopped = sim.state(1)["angle"]
        with _Watch(sim) as watch:
            sim.sleep(1.5)
        assert max(abs(a - stopped) for a in watch.seen) < 0.2, (stopped, min(watch.seen), max(watch.seen))
    finally:
        other.close()


def test_a_drag_that_goes_on_after_another_tabs_stop_all_jogs_nothing(bench):
    """The driving tab's drag (input events every 8 ms about the servo's
    angle) went on after a watching tab's STOP ALL, and each jog after it
    drove the servo again (round-5 review). Now the slider holds until the
    hand on it lets go (a pointerup or keyup), which a drag has not."""
    sim, page = bench
    page.click("#tabs button[data-view=motion]")
    at = round(sim.state(1)["angle"])
    page.wait_for_function(f"!document.querySelector('#jog').disabled"
                           f" && document.querySelector('#jog').value === '{at}'", timeout=WAIT_MS)
    other = page.context.new_page()
    try:
        other.goto(page.url)
        other.locator("#role", has_text="watching").wait_for(timeout=WAIT_MS)
        page.bring_to_front()
        page.evaluate(f"""() => {{ const j = document.querySelector('#jog'); let k = 0;
            window.dragging = setInterval(() => {{ j.value = String({at} + (k++ % 2));
                j.dispatchEvent(new Event('input')); }}, 8); }}""")
        sim.sleep(0.5)
        other.click("#stop-all")
        page.locator("#log", has_text="stop-all:").wait_for(timeout=WAIT_MS)
        stopped = sim.state(1)["angle"]  # a jog after the stop ran 250-460 ms after it
        with _Watch(sim) as watch:
            sim.sleep(1.5)
        page.evaluate("() => clearInterval(window.dragging)")
        assert max(abs(a - stopped) for a in watch.seen) < 0.3, (stopped, min(watch.seen), max(watch.seen))
        assert page.inner_text("#jog-at") == "stopped: let go of the slider to jog again"
        page.keyboard.up("Shift")  # a hand let go: the slider jogs again
        page.wait_for_function("!document.querySelector('#jog').disabled", timeout=WAIT_MS)
    finally:
        other.close()


def test_the_servo_view_says_an_item_out_of_order_in_the_unit_typed(bench):
    """angle_min 100 with angle_max 90 was said "servo 1 refused angle_min
    = 1000": protocol units, no reason."""
    _, page = bench
    page.click("#tabs button[data-view=servo]")
    for name, value in (("angle_max", "90"), ("angle_min", "100")):
        field = page.locator(f"#items tr[data-item={name}] input")
        field.wait_for(timeout=WAIT_MS)
        field.fill(value)
        field.press("Enter")
    why = page.locator("#items tr[data-item=angle_min] td.why")
    why.filter(has_text="angle_min = 100.0 deg not sent: angle_min must stay below angle_max (90.0 deg now): "
                        "set angle_max above 100.0 deg first").wait_for(timeout=WAIT_MS)

