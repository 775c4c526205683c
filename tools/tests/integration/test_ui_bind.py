"""servoctl ui without a browser: its first line is an address a browser
opens, whatever --bind says (urllib asks for the page); what a tab sends
that is not a request is answered with an error and leaves it connected;
every response forbids framing; the Origin is the listening address's;
connections without the token are capped and timed out; a closed tab's
command and sampling end with it."""
import asyncio
import json
import socket
import time
import urllib.error
import urllib.request

import pytest

from servoctl.sim import Simulator
from ..ui_launch import UiProcess, http_status as _status


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


def _ws_url(ui):
    return ui.base.replace("http", "ws", 1) + "/ws?token=" + ui.token


async def _next(ws, aiohttp, what):
    """The next message what(msg) is true of; a closed socket fails."""
    while True:
        msg = await ws.receive(timeout=20)
        assert msg.type == aiohttp.WSMsgType.TEXT, f"the tab's connection ended: {msg}"
        said = json.loads(msg.data)
        if what(said):
            return said


def test_every_malformed_message_is_answered_with_an_error():
    """{"id": Infinity} and JSON nested 100 000 deep dropped the tab's
    connection (and the driving role passed on); now each is answered with
    an error, in order, and the tab goes on driving."""
    aiohttp = pytest.importorskip("aiohttp")
    bad = ('{"op": "items", "id": Infinity}', '{"op": "plot", "ids": [NaN]}', "[" * 100000 + "]" * 100000,
           '{"a": ' * 100000 + "1" + "}" * 100000, '{"op": "run", "argv": {"x": 1}}', '{"op": "items", "id": 1e400}',
           '{"op": "plot", "ids": 5}', '{"op": "nothing"}', b"\xff\xfe",
           # fields of the wrong type: "false" ran a scan of every baud rate, a list released
           '{"op": "scan", "all_bauds": "false"}', '{"op": "stopmode", "mode": [1]}')

    async def talk(ui):
        async with aiohttp.ClientSession() as s:
            async with s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}) as ws:
                errors = []
                for message in bad:
                    await (ws.send_bytes if isinstance(message, bytes) else ws.send_str)(message)
                    errors.append(await _next(ws, aiohttp, lambda m: m["type"] == "error"))
                await ws.send_str(json.dumps({"op": "run", "argv": ["ping", "1"], "tag": "t"}))
                return errors, await _next(ws, aiohttp, lambda m: m["type"] == "result")

    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim) as ui:
        errors, result = asyncio.run(talk(ui))
        code, err = ui.stop()
    assert all("malformed request" in e["text"] for e in errors), errors
    assert result["code"] == 0, result
    assert code == 0 and "Traceback" not in err, err


def test_every_response_forbids_framing():
    """No X-Frame-Options or CSP frame-ancestors: another site could frame
    the page and have its STOP or move buttons clicked through."""
    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim) as ui:
        for url in (ui.url, ui.base + "/static/app.js?token=" + ui.token, ui.base + "/"):
            try:
                with urllib.request.urlopen(url, timeout=10) as r:
                    headers = r.headers
            except urllib.error.HTTPError as e:  # the one without the token: 403, framed neither
                headers = e.headers
            assert headers["X-Frame-Options"] == "DENY", url
            assert "frame-ancestors 'none'" in headers["Content-Security-Policy"], url
        # A Host that is no host and port was a 500 (yarl's ValueError): refused as any other.
        port = ui.base.rsplit(":", 1)[1]
        assert _status(ui.url, host="127.0.0.1:abc") == 403
        assert _status(ui.url, host=f"127.0.0.1:{port}, evil.example") == 403


def test_the_origin_is_compared_with_the_address_it_listens_on():
    """The Origin was compared with the request's own Host header: a page
    of a name rebound to this computer sends both alike. Listening on
    0.0.0.0 (no check of the host name), it drove the bus."""
    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim, ["--bind", "0.0.0.0"]) as ui:
        port = ui.base.rsplit(":", 1)[1]
        rebound = f"rebound.example:{port}"
        assert _status(ui.url, origin=f"http://{rebound}", host=rebound) == 403
        assert _status(ui.url, origin=ui.base) == 200
        assert _status(ui.url.replace("127.0.0.1", "localhost"), origin=f"http://localhost:{port}") == 200


def test_connections_without_the_token_are_capped_and_timed_out():
    """Half-open connections without the token were never closed: 3000 took
    every file descriptor and page loads timed out. Now at most
    UNTRUSTED_MAX are open (the oldest closed first), each for 10 s at
    most, and a page load with the token still comes through."""
    from servoctl.ui.doorman import UNTRUSTED_MAX
    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim) as ui:
        port = int(ui.base.rsplit(":", 1)[1])
        idle = []
        for _ in range(UNTRUSTED_MAX + 72):
            c = socket.create_connection(("127.0.0.1", port), timeout=10)
            c.sendall(b"GET /?token=" + ui.token.encode() + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n")  # never ends
            idle.append(c)
        assert _status(ui.url) == 200
        deadline = time.monotonic() + 5  # host time: a bound on failure only
        while sum(not _closed(c) for c in idle) > UNTRUSTED_MAX:
            assert time.monotonic() < deadline, f"{sum(not _closed(c) for c in idle)} of {len(idle)} still open"
            time.sleep(0.05)
        deadline = time.monotonic() + 30  # the 10 s limit, and a bound on failure only
        while not all(_closed(c) for c in idle):
            assert time.monotonic() < deadline, "connections without a whole request stay open"
            time.sleep(0.2)
        for c in idle:
            c.close()
        code, err = ui.stop()
    assert code == 0 and "Traceback" not in err, err


def test_a_closed_tabs_command_and_sampling_end_with_it():
    """A tab closed mid-action left its command (a 5 s move that waits)
    and its plot's sampling running; the next tab waited behind them."""
    aiohttp = pytest.importorskip("aiohttp")

    async def talk(ui, sim):
        async with aiohttp.ClientSession() as s:
            async with s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}) as ws:
                await ws.send_str(json.dumps({"op": "plot", "ids": [1]}))
                await _next(ws, aiohttp, lambda m: m["type"] == "samples")
                await ws.send_str(json.dumps({"op": "run", "argv": ["move", "1", "90", "--interval", "5000",
                                                                    "--wait"], "tag": 1}))
                sim.wait_until(lambda: abs(sim.state(1)["velocity"]) > 5, timeout_s=5)  # under way
            closed_at = sim.clock_s()
            async with s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}) as ws:
                await ws.send_str(json.dumps({"op": "run", "argv": ["ping", "1"], "tag": 2}))
                said = await _next(ws, aiohttp, lambda m: m["type"] == "result" and m["tag"] == 2)
                waited = sim.clock_s() - closed_at
                sim.sleep(0.3)
                await ws.send_str(json.dumps({"op": "run", "argv": ["ping", "1"], "tag": 3}))
                after = []
                while not after or after[-1].get("tag") != 3:
                    after.append(await _next(ws, aiohttp, lambda m: m["type"] in ("samples", "result")))
                return said, waited, after

    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim) as ui:
        said, waited, after = asyncio.run(talk(ui, sim))
    assert said["code"] == 0 and waited < 1.0, (said.get("err"), said.get("text"), said, waited)  # not behind the 5 s move
    assert not [m for m in after if m["type"] == "samples"], "the closed tab's plot is still sampled"


def _closed(c) -> bool:
    """Whether the server has closed c (its end read, or reset)."""
    c.setblocking(False)
    try:
        return c.recv(4096) == b""
    except BlockingIOError:
        return False
    except OSError:
        return True
