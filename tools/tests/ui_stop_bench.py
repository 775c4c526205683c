"""STOP ALL's time from the click to the stopped servo, on the simulator's
clock, for each thing `servoctl ui`'s bus thread may be busy with (docs/ui.md,
"STOP ALL"); scripts/ui_stop_bench.py prints the table, test_ui_stop.py
checks some cases.

The bus: servo 1 turns as a wheel, servo 2 is the one a command works on,
and SILENT servos more answered the first scan and were then unplugged
(servo_sim's `unplug`), so the live table's round waits for each. The click
is the page's message ({"op": "stopall", "mode": "release"}) on the
WebSocket, sent at the simulator's clock t0; the servo is stopped when
servo_sim reports its H-bridge let go (`coasted_ms` of servo 1, on the same
clock). The simulator runs in real time (neither fast nor paced): the
host's reaction is in its clock, as a real servo would see it."""
import asyncio
import json
import re
import tempfile
from pathlib import Path

import aiohttp

from servoctl import image as img
from servoctl.sim import Simulator

from .ui_launch import UiProcess

WHEEL, WORKED_ON = 1, 2
LIMIT_MS = 50.0
WAIT_S = 30.0  # host seconds for a message the bench waits for (a bound: on failure)


def _run(*argv):
    return {"op": "run", "argv": list(argv)}


def _last_step(msg) -> bool:
    """identify's "step N/N": its experiment done, the fit begins."""
    return msg["type"] == "line" and re.fullmatch(r"\s*step (\d+)/\1", msg["text"]) is not None


# name, what starts it (None: nothing, the page's idle round), the message
# that says it is under way (its type, or a test of it), then simulated
# seconds before the click.
SITUATIONS = {
    "idle live-table round": (None, "table", 1.1),
    "plot sampling": ({"op": "plot", "ids": "all"}, "samples", 0.3),
    "scan of all baud rates": ({"op": "scan", "all_bauds": True}, None, 2.5),
    "bring-up (id bringup)": (_run("id", "bringup", "--from-id", "0", "--first", "20", "--wait-s", "30"),
                              None, 0.5),
    "identify, as it starts (the fit's import)": (_run("identify", str(WORKED_ON)), None, 0.02),
    "identify": (_run("identify", str(WORKED_ON)), "line", 0.3),
    "identify's fit": (_run("identify", str(WORKED_ON)), _last_step, 0.0),
    "tune": (_run("tune", str(WORKED_ON), "--dry-run"), "line", 0.3),
    "calibrate": (_run("calibrate", str(WORKED_ON)), "line", 0.3),
    "64 page actions queued": ("queue", None, 0.2),
    "update between blocks": (_run("update", str(WORKED_ON), "stop-bench.img"), "progress", 0.0),
}


class Page:
    """One tab's WebSocket: what it sends, and every message it heard."""

    def __init__(self, ws, sim):
        self.ws, self.sim, self.heard, self.tag = ws, sim, [], 0

    async def send(self, msg: dict) -> int:
        self.tag += 1
        await self.ws.send_str(json.dumps({**msg, "tag": self.tag}))
        return self.tag

    async def until(self, what, since: int = 0) -> dict:
        """The first message from heard[since:] that what(msg) is true of."""
        deadline = asyncio.get_running_loop().time() + WAIT_S
        while True:
            for msg in self.heard[since:]:
                if what(msg):
                    return msg
            since = len(self.heard)
            left = deadline - asyncio.get_running_loop().time()
            assert left > 0, f"not heard within {WAIT_S} s: {self.heard[-3:]}"
            msg = await self.ws.receive(timeout=left)
            assert msg.type == aiohttp.WSMsgType.TEXT, msg
            self.heard.append(json.loads(msg.data))

    async def result(self, tag: int) -> dict:
        return await self.until(lambda m: m.get("tag") == tag and m["type"] in ("result", "error"))

    async def sim_sleep(self, seconds: float):
        end = self.sim.clock_s() + seconds
        while self.sim.clock_s() < end:
            await asyncio.sleep(0.002)


async def _one(page: Page, sim, ids: list, name: str) -> dict:
    start, sign, delay_s = SITUATIONS[name]
    tag = await page.send({"op": "run", "argv": ["wheel", str(WHEEL), "run", "--speed", "180"]})
    assert (await page.result(tag))["code"] == 0
    while abs(sim.state(WHEEL)["velocity"]) < 30:
        await page.sim_sleep(0.01)
    mark = len(page.heard)
    tag = None
    if start == "queue":
        tag = await page.send(_run("move", str(WORKED_ON), "30", "--interval", "3000", "--wait"))
        for _ in range(64):
            await page.send(_run("ping", str(WORKED_ON)))
    elif start is not None:
        tag = await page.send({**start, "ids": ids} if start.get("ids") == "all" else start)
    if sign:
        await page.until(sign if callable(sign) else lambda m: m["type"] == sign, mark)
    await page.sim_sleep(delay_s)
    t0_ms = sim.clock_s() * 1000.0
    clicked = len(page.heard)
    await page.send({"op": "stopall", "mode": "release"})
    while (coasted := sim.state(WHEEL)["coasted_ms"]) < t0_ms:
        await asyncio.sleep(0.001)
    await page.until(lambda m: m["type"] == "stopped", clicked)
    # Under way at the click: the command ended after it (interrupted, or in
    # its last step, a fit, with no bus step left), or queued ones went unrun.
    under_way = None
    if start is not None and start != "queue" and start["op"] != "plot":
        done = await page.until(lambda m: m["type"] in ("result", "scan") and m.get("tag", tag) == tag, mark)
        under_way = page.heard.index(done) >= clicked
    elif start == "queue":
        under_way = any(m["type"] == "result" and "not run" in m["err"] for m in page.heard[clicked:])
    if start is not None and start != "queue" and start["op"] == "plot":
        await page.send({"op": "plot", "ids": []})
        await page.until(lambda m: m["type"] == "plotting" and not m["ids"], clicked)
    return {"situation": name, "ms": coasted - t0_ms, "under_way": under_way}


async def _bench(ui, sim, ids, silent_ids, names):
    async with aiohttp.ClientSession() as session:
        url = ui.base.replace("http", "ws", 1) + "/ws?token=" + ui.token
        async with session.ws_connect(url, headers={"Origin": ui.base}, max_msg_size=0) as ws:
            page = Page(ws, sim)
            await page.send({"op": "scan"})
            await page.until(lambda m: m["type"] == "scan")
            for servo_id in silent_ids:
                sim.control(f"unplug 1 {servo_id}")
            return [await _one(page, sim, ids, name) for name in names]


def measure(silent: int, names=tuple(SITUATIONS)) -> list:
    """[{situation, ms, under_way}] on a bus of servos 1 and 2 and
    silent unplugged ones."""
    silent_ids = list(range(3, 3 + silent))
    ids = [WHEEL, WORKED_ON] + silent_ids
    with tempfile.TemporaryDirectory(prefix="servoctl-stop-bench-") as files:
        image = img.build(bytes(range(256)) * 24, 0x0042, img.BOARDS["host_sim"])
        Path(files, "stop-bench.img").write_bytes(image)
        with Simulator(ids=ids) as sim, UiProcess(sim, ["--files", files]) as ui:
            return asyncio.run(_bench(ui, sim, ids, silent_ids, names))
