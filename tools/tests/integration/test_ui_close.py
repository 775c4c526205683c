"""What a driving tab set moving ends with it (docs/ui.md, "One tab drives
the bus"): when it closes, every servo of the last scan is stopped as its
STOP ALL would (release, or damping where its page chose damp), the other
tabs told; with no tab open, the ui sends nothing on the bus, so a servo's
bus watchdog (item 64) is fed by nobody and acts. Before, a wheel run by a
closed tab turned on, and the live table's `info` every second fed its
watchdog, which never fired. Time is the simulator's (real time)."""
import asyncio
import json

import pytest

from servoctl.sim import Simulator
from ..ui_launch import UiProcess
from ..ui_stop_bench import Page
from .test_ui_flood import _ws_url

aiohttp = pytest.importorskip("aiohttp")

STOPPED_MS = 500.0  # simulator ms from the close to the stop: as STOP ALL's bound (test_ui_stop.py)


async def _close_driving(ui, sim, mode, keep_watcher: bool):
    async with aiohttp.ClientSession() as s:
        driver = Page(await s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}), sim)
        await driver.until(lambda m: m["type"] == "hello" and m["role"] == "driver")
        watcher = None
        if keep_watcher:
            watcher = Page(await s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}), sim)
            await watcher.until(lambda m: m["type"] == "hello")
        if mode is not None:
            await driver.ws.send_str(json.dumps({"op": "stopmode", "mode": mode}))
        await driver.send({"op": "scan"})
        await driver.until(lambda m: m["type"] == "scan")
        for argv in (["config", "set", "1", "watchdog_ms", "1500"], ["config", "set", "1", "watchdog_action", "2"],
                     ["wheel", "1", "run", "--speed", "90"]):
            said = await driver.result(await driver.send({"op": "run", "argv": argv}))
            assert said["code"] == 0, said
        await driver.sim_sleep(0.5)
        assert abs(sim.state(1)["velocity"]) > 30
        closed_ms = sim.clock_s() * 1000.0
        await driver.ws.close()
        heard = None
        if watcher is not None:
            heard = await watcher.until(lambda m: m["type"] == "stopped")
        # The stop on the simulator's own record: when the bridge let go
        # (released), or the state that first shows the horn still, at its
        # own instant (damped); not when this loop, late on a loaded PC,
        # looked.
        while abs((state := sim.state(1))["velocity"]) > 5 or (mode is None and state["coasted_ms"] < closed_ms):
            assert state["sim_ms"] - closed_ms < 5000, "the closed tab's wheel turns on"
            await asyncio.sleep(0.005)
        stopped_ms = (state["coasted_ms"] if mode is None else state["sim_ms"]) - closed_ms
        # The ui's stop done: it ends with each known servo's own stop,
        # servo 2's last, answered. Only from there is the bus quiet.
        while sim.state(2)["last_sent_ms"] < closed_ms:
            assert sim.clock_s() * 1000.0 - closed_ms < 5000, "the ui's stop never reached servo 2"
            await asyncio.sleep(0.005)
        quiet_from = sim.state(1)["heard_ms"]
        await driver.sim_sleep(3.0)  # three of the live table's rounds, were there any
        quiet = sim.state(1)["heard_ms"] == quiet_from
        if watcher is not None:
            await watcher.ws.close()
        return stopped_ms, heard, quiet, sim.state(1)


@pytest.mark.parametrize("mode", [None, "damping"])
def test_the_driving_tabs_close_stops_what_it_set_moving(mode):
    with Simulator(ids=[1, 2]) as sim, UiProcess(sim) as ui:
        stopped_ms, heard, _, state = asyncio.run(_close_driving(ui, sim, mode, True))
        code, err = ui.stop()
    print(f"stopped {stopped_ms:.1f} ms after the close")
    assert stopped_ms <= STOPPED_MS, stopped_ms
    assert heard["mode"] == (mode or "release") and heard["ids"] == [1, 2] and not heard["failed"], heard
    if mode is None:  # released at once: the bridge let go
        assert state["coasted_ms"] > 0, state
    assert code == 0 and "Traceback" not in err, err[:2000]


def test_with_no_tab_open_the_bus_is_quiet():
    with Simulator(ids=[1, 2]) as sim, UiProcess(sim) as ui:
        stopped_ms, _, quiet, _ = asyncio.run(_close_driving(ui, sim, None, False))
        code, err = ui.stop()
    assert stopped_ms <= STOPPED_MS, stopped_ms
    assert quiet, "the ui still talks to the servos with no tab open: it feeds their bus watchdog"
    assert code == 0 and "Traceback" not in err, err[:2000]


async def _spin_and_stay(ui, sim):
    async with aiohttp.ClientSession() as s:
        driver = Page(await s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}), sim)
        await driver.send({"op": "scan"})
        await driver.until(lambda m: m["type"] == "scan")
        said = await driver.result(await driver.send({"op": "run", "argv": ["wheel", "1", "run", "--speed", "90"]}))
        assert said["code"] == 0, said
        await driver.sim_sleep(0.5)
        code, err = ui.stop()  # Ctrl-C with the tab still open and driving
        await driver.sim_sleep(1.0)
        return code, err, sim.state(1)


def test_stopping_the_ui_leaves_the_servos_as_they_are():
    """Ctrl-C stops the ui, not the servos (as every servoctl command): its
    tabs' close at shutdown is not a driving tab going away."""
    with Simulator(ids=[1]) as sim, UiProcess(sim) as ui:
        code, err, state = asyncio.run(_spin_and_stay(ui, sim))
    assert code == 0 and "Traceback" not in err, err[:2000]
    assert abs(state["velocity"]) > 30 and state["coasted_ms"] == 0, state
