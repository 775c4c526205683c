"""servoctl ui's STOP ALL against a tab opening while it runs: with a known
servo silent, "stopped" comes 0.7 s after the stop, and a hello in between
told the driving tab the new stop count without holding its slider. In
Debian's chromium driven by Playwright against servo_sim; the horn is
judged on the simulator's state. Its own module: the jog tests' module
keeps a Playwright of its own open."""
import shutil
from pathlib import Path

import pytest

from servoctl.sim import Simulator
from ..ui_launch import CHROMIUM, UiProcess, launch_chromium
from .test_ui_jog import WAIT_MS, _Watch, rest_servo_1

playwright_api = pytest.importorskip("playwright.sync_api")

def test_a_tab_opening_during_a_stop_lets_no_jog_through():
    """With a known servo silent, STOP ALL's "stopped" comes 0.7 s after
    the stop; a tab opening meanwhile told the driving tab the new count,
    and its drag's next jog ran and held the servo (round-7 review)."""
    if not Path(CHROMIUM).exists():
        pytest.fail(f"no {CHROMIUM}: scripts/setup.sh installs Debian's chromium")
    with Simulator(ids=[1, 2]) as sim:
        rest_servo_1(sim)
        with playwright_api.sync_playwright() as pw, UiProcess(sim) as ui:
            context, profile = launch_chromium(pw)
            try:
                a = context.new_page()
                a.goto(ui.url)
                a.locator("#bus-table tr[data-id='2'] td.state", has_text="answering").wait_for(timeout=WAIT_MS)
                sim.control("unplug 1 2")
                a.click("#tabs button[data-view=motion]")
                b = context.new_page()
                b.goto(ui.url)
                b.locator("#role", has_text="watching").wait_for(timeout=WAIT_MS)
                a.bring_to_front()
                at = round(sim.state(1)["angle"])
                a.wait_for_function(f"!document.querySelector('#jog').disabled"
                                    f" && document.querySelector('#jog').value === '{at}'", timeout=WAIT_MS)
                # A step, then the hand rests on the slider: no jog in flight at the stop.
                a.evaluate(f"() => {{ const j = document.querySelector('#jog'); j.value = '{at + 1}';"
                           f" j.dispatchEvent(new Event('input')); }}")
                a.locator("#motion-out", has_text=f"servo 1: at {at + 1}").wait_for(timeout=WAIT_MS)
                sim.sleep(0.3)
                a.evaluate("() => { window.heard = []; UI.on('stopped', () => heard.push('stopped')); }")
                b.evaluate("() => document.querySelector('#stop-all').click()")
                c = context.new_page()
                c.goto(ui.url)  # its hello reaches every tab before "stopped" (a silent servo's 0.7 s)
                a.evaluate(f"""() => {{ const j = document.querySelector('#jog'); let k = 0;
                    window.dragging = setInterval(() => {{ j.value = String({at + 2} + (k++ % 2));
                        j.dispatchEvent(new Event('input')); }}, 8); }}""")
                a.wait_for_function("heard.length > 0", timeout=WAIT_MS)
                stopped = sim.state(1)["angle"]
                with _Watch(sim) as watch:
                    sim.sleep(1.5)
                a.evaluate("() => clearInterval(window.dragging)")
                assert max(abs(x - stopped) for x in watch.seen) < 0.3, (stopped, min(watch.seen), max(watch.seen))
                assert sim.state(1)["mode"] != "position", sim.state(1)["mode"]  # released, not held again
            finally:
                context.close()
                shutil.rmtree(profile, ignore_errors=True)
