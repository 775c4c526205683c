"""servoctl ui without a browser: its first line is an address a browser
opens, whatever --bind says (urllib asks for the page), and what a tab
sends that is not a request leaves it connected."""
import asyncio
import json
import urllib.request

import pytest

from servoctl.sim import Simulator
from ..ui_launch import UiProcess


def test_the_address_of_an_ipv6_bind_opens_the_page():
    """--bind ::1 printed http://::1:PORT/?token=..., which no browser
    opens: an IPv6 address goes in brackets."""
    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim, ["--bind", "::1"]) as ui:
        assert ui.url.startswith("http://[::1]:"), ui.first_line
        with urllib.request.urlopen(ui.url, timeout=10) as r:
            assert r.status == 200 and b"STOP ALL" in r.read()


def test_a_malformed_request_leaves_the_tab_connected():
    """A request that is JSON but not an object, or lacks a field, closed
    the tab's WebSocket with a traceback on the server."""
    aiohttp = pytest.importorskip("aiohttp")

    async def talk(ui):
        async with aiohttp.ClientSession() as s:
            url = ui.base.replace("http", "ws", 1) + "/ws?token=" + ui.token
            async with s.ws_connect(url, headers={"Origin": ui.base}) as ws:
                for bad in ("[1, 2]", "5", '{"op": "items"}', '{"op": "items", "id": "x"}'):
                    await ws.send_str(bad)
                await ws.send_str(json.dumps({"op": "run", "argv": ["ping", "1"], "tag": "t"}))
                while True:
                    msg = await ws.receive(timeout=20)
                    assert msg.type == aiohttp.WSMsgType.TEXT, msg
                    said = json.loads(msg.data)
                    if said.get("type") == "result":
                        return said

    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim) as ui:
        said = asyncio.run(talk(ui))
        assert said["code"] == 0, said
        code, err = ui.stop()
    assert code == 0 and "Traceback" not in err, err
