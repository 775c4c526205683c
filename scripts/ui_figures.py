#!/usr/bin/env python3
"""servoctl ui's figures in docs/ui.md, measured in the browser: the page's
load time (Navigation Timing, the median of several loads) and the live
plot's samples a second of each servo (counted by the page over the last
2 s of the samples' own timestamps, the simulator's clock), for 1, 2 and 6
servos plotted. servo_sim with 6 servos at 115200 baud, headless Debian
chromium (tools/tests/ui_launch.py).

    .venv/bin/python scripts/ui_figures.py   (after the host build)"""
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

from playwright.sync_api import sync_playwright  # noqa: E402

from servoctl.sim import Simulator  # noqa: E402
from tests.ui_launch import UiProcess, launch_chromium, navigation_ms  # noqa: E402

LOADS = 5
SAMPLE_S = 4.0  # host seconds a plot runs before it is read


def main() -> int:
    with Simulator(ids=[1, 2, 3, 4, 5, 6]) as sim, UiProcess(sim) as ui, sync_playwright() as pw:
        context, _ = launch_chromium(pw)
        page = context.new_page()
        loads = []
        for _ in range(LOADS):
            page.goto(ui.url)
            page.wait_for_function("document.querySelectorAll('#bus-table tbody tr').length === 6", timeout=20000)
            loads.append(navigation_ms(page))
        print("| figure | measured |")
        print("|---|---|")
        for key, what in (("dom_ready_ms", "DOM ready"), ("load_ms", "loaded (load event ends)")):
            ms = [round(x[key], 1) for x in loads]
            print(f"| page {what}, median of {LOADS} loads | {statistics.median(ms):.0f} ms "
                  f"(each: {', '.join(f'{m:.0f}' for m in ms)}) |")
        for ids in ([1], [1, 2], [1, 2, 3, 4, 5, 6]):
            page.evaluate(f"UI.send({{op: 'plot', ids: {ids}}})")
            time.sleep(SAMPLE_S)
            rates = page.evaluate("servoUiPlots.rates()")
            low = min(rates.values())
            print(f"| live plot, {len(ids)} servo(s): samples a second of each (simulated clock) | "
                  f"{low:.0f} at least ({', '.join(f'{v:.0f}' for v in rates.values())}) |")
        page.evaluate("UI.send({op: 'plot', ids: []})")
        print(f"| the machine's load average (1 min) when done | {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs |")
        context.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
