"""servoctl ui under a flood (docs/ui.md, "Safe by default"): STOP ALL
still preempts while a watching tab floods the server with large and
compressed messages, and while requests without the token are malformed
and aiohttp would log each, with the server's stderr a pipe nobody reads.
Before: a watching tab's 4 KB compressed frames inflating to 4 MB, ten a
second, held STOP ALL for 13.9 s; 2 865 malformed requests printed 20 620
lines of tracebacks, and a full stderr pipe held the server's loop so STOP
ALL never reached the wire. Also: a message too long for a request is
answered with an error, the tab still driving; tabs and connections
without the token are capped; the Host header is checked as the request
line is. Floods are on 127.0.0.1, bounded in count and time."""
import asyncio
import base64
import json
import os
import socket
import time

import pytest

from servoctl.sim import Simulator
from ..ui_launch import UiProcess, http_status as _status
from ..ui_stop_bench import Page

aiohttp = pytest.importorskip("aiohttp")

PREEMPTED_MS = 500.0  # simulator ms: a stop that preempts (test_ui_stop.py), not one behind seconds of work
WAIT_S = 20.0         # host seconds: a bound on failure only
INFLATES = '{"op": "run", "argv": [' + "1," * 1_999_990 + '1]}'  # 4 MB of JSON, 4 KB deflated


def _ws_url(ui):
    return ui.base.replace("http", "ws", 1) + "/ws?token=" + ui.token


async def _drain(ws, heard):
    """Reads whatever the server says to ws until it closes."""
    while True:
        msg = await ws.receive()
        if msg.type != aiohttp.WSMsgType.TEXT:
            return
        heard.append(json.loads(msg.data))


async def _stop_ms(page, sim) -> float:
    """The wheel turned by the driving tab, STOP ALL clicked on it: ms on
    the simulator's clock from the click to the H-bridge let go."""
    t0_ms = sim.clock_s() * 1000.0
    await page.send({"op": "stopall", "mode": "release"})
    deadline = time.monotonic() + WAIT_S
    while (coasted := sim.state(1)["coasted_ms"]) < t0_ms:
        assert time.monotonic() < deadline, "STOP ALL did not reach the wire"
        await asyncio.sleep(0.002)
    return coasted - t0_ms


async def _spin(page, sim):
    tag = await page.send({"op": "run", "argv": ["wheel", "1", "run", "--speed", "180"]})
    assert (await page.result(tag))["code"] == 0
    while abs(sim.state(1)["velocity"]) < 30:
        await page.sim_sleep(0.01)


async def _flood_and_stop(ui, sim):
    async with aiohttp.ClientSession() as s:
        async with s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}, max_msg_size=0) as driver, \
                s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}, compress=15) as deflating, \
                s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}) as plain:
            page = Page(driver, sim)
            readers = [asyncio.ensure_future(_drain(ws, [])) for ws in (deflating, plain)]
            await _spin(page, sim)

            async def flood():
                for _ in range(60):  # 6 s at most
                    await deflating.send_str(INFLATES)  # deflated if the server accepts it
                    await plain.send_str('{"op": "stopall", "x": "' + "A" * 1_000_000 + '"}')
                    await asyncio.sleep(0.1)
            flooding = asyncio.ensure_future(flood())
            await page.sim_sleep(1.0)
            ms = await _stop_ms(page, sim)
            flooding.cancel()
            for r in readers:
                r.cancel()
            return ms, deflating.compress


def test_stop_all_preempts_a_watching_tabs_flood():
    with Simulator(ids=[1, 2]) as sim, UiProcess(sim) as ui:
        ms, compress = asyncio.run(_flood_and_stop(ui, sim))
        code, err = ui.stop()
    assert compress == 0, "permessage-deflate was accepted"
    assert ms <= PREEMPTED_MS, ms
    assert code == 0 and "Traceback" not in err, err


MALFORMED = (b"GET / HTTP/1.1\r\n\r\n",  # no Host header
             b"POST / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: x\r\n\r\n",
             b"GET /" + b"a" * 9000 + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")


def _malformed(port: int, count: int) -> list:
    """count malformed requests without the token, one a connection: the
    status lines answered (None: none came within the bound)."""
    answers = []
    for i in range(count):
        # WAIT_S a guard only: a loaded PC may leave the server's answer
        # seconds behind; one that stopped answering (a full stderr) never answers.
        with socket.create_connection(("127.0.0.1", port), timeout=WAIT_S) as c:
            c.sendall(MALFORMED[i % len(MALFORMED)])
            try:
                answers.append(c.recv(64).split(b"\r\n", 1)[0])
            except OSError:
                answers.append(None)
                break  # the server stopped answering: no more
    return answers


async def _stop_after(ui, sim):
    async with aiohttp.ClientSession() as s:
        async with s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}) as driver:
            page = Page(driver, sim)
            await _spin(page, sim)
            return await _stop_ms(page, sim)


def test_malformed_requests_log_a_line_a_second_and_an_unread_stderr_holds_nothing():
    """UiProcess's stderr is a pipe this test reads only once the ui has
    stopped: 64 KiB of log would fill it."""
    with Simulator(ids=[1, 2]) as sim, UiProcess(sim) as ui:
        started = time.monotonic()
        answers = _malformed(int(ui.base.rsplit(":", 1)[1]), 600)
        ms = asyncio.run(_stop_after(ui, sim))
        took_s = time.monotonic() - started
        code, err = ui.stop()
    assert len(answers) == 600 and all(a and a.split()[1].startswith(b"4") for a in answers), answers[-3:]
    assert ms <= PREEMPTED_MS, ms
    lines = err.splitlines()
    assert len(lines) <= 4 + took_s + 2, lines[:20]  # start, stop, and a line a second at most
    assert code == 0 and "Traceback" not in err, err[:2000]


async def _too_long(ui):
    async with aiohttp.ClientSession() as s:
        async with s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}) as ws:
            heard = []
            for size in (100_000, 5_000_000):
                await ws.send_str(json.dumps({"op": "table", "tag": size, "x": "A" * size}))
                heard.append({})
                while heard[-1].get("type") != "error":
                    msg = await ws.receive(timeout=WAIT_S)
                    assert msg.type == aiohttp.WSMsgType.TEXT, f"the tab's connection ended: {msg}"
                    heard.append(json.loads(msg.data))
            errors = [m for m in heard if m.get("type") == "error"]
            await ws.send_str(json.dumps({"op": "run", "argv": ["ping", "1"] * 40, "tag": "words"}))
            await ws.send_str(json.dumps({"op": "run", "argv": ["ping", "1"], "tag": "t" * 100}))
            await ws.send_str(json.dumps({"op": "run", "argv": ["ping", "1"], "tag": "ok"}))
            while heard[-1].get("type") != "result":
                msg = await ws.receive(timeout=WAIT_S)
                assert msg.type == aiohttp.WSMsgType.TEXT, f"the tab's connection ended: {msg}"
                heard.append(json.loads(msg.data))
            return errors, [m for m in heard if m.get("type") in ("error", "result")][-3:]


def test_a_message_too_long_for_a_request_is_answered_with_an_error():
    """A message of 4 MiB or more closed the tab's connection (aiohttp's
    limit) instead of an error; now anything over 64 KiB is refused by its
    length, unparsed, up to 16 MiB read, and the tab goes on driving."""
    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim) as ui:
        errors, last = asyncio.run(_too_long(ui))
    assert [e["tag"] for e in errors] == [None, None], errors
    assert all("malformed request" in e["text"] and "bytes long" in e["text"] for e in errors), errors
    assert "malformed request" in last[0]["text"] and "words" in last[0]["text"], last
    assert "malformed request" in last[1]["text"] and "tag" in last[1]["text"], last
    assert last[2]["type"] == "result" and last[2]["code"] == 0, last


async def _tabs(ui, count):
    async with aiohttp.ClientSession() as s:
        tabs, said = [], []
        try:
            for _ in range(count):
                tabs.append(await s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}))
            msg = await tabs[-1].receive(timeout=WAIT_S)
            said.append(json.loads(msg.data))
            said.append((await tabs[-1].receive(timeout=WAIT_S)).type)
            said.append(tabs[0].closed)
        finally:
            for ws in tabs:
                await ws.close()
        return said


def test_open_tabs_are_capped_with_a_message():
    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim) as ui:
        said = asyncio.run(_tabs(ui, 9))
    assert said[0]["type"] == "error" and "8 tabs are open" in said[0]["text"], said
    assert said[1] in (aiohttp.WSMsgType.CLOSE, aiohttp.WSMsgType.CLOSED), said
    assert said[2] is False, "the first tab was closed"


def test_the_host_header_is_checked_as_the_request_line_is():
    """GET http://127.0.0.1:PORT/?token=T with Host: evil.com was let in:
    the host check read the request line's host alone."""
    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim) as ui:
        port = int(ui.base.rsplit(":", 1)[1])
        answers = []
        for host in (b"evil.com", b"127.0.0.1:%d" % port):
            with socket.create_connection(("127.0.0.1", port), timeout=WAIT_S) as c:
                c.sendall(b"GET " + ui.url.encode() + b" HTTP/1.1\r\nHost: " + host + b"\r\n\r\n")
                answers.append(c.recv(64).split(b"\r\n", 1)[0])
        assert _status(ui.url, host="evil.com") == 403
    assert answers[0].startswith(b"HTTP/1.1 403") and answers[1].startswith(b"HTTP/1.1 200"), answers


def test_a_request_under_way_is_closed_after_idle_connections():
    """At the cap of connections without the token, the oldest was closed
    for a new one even with its request half sent: a page load under a
    flood of idle connections was reset. Now idle ones go first."""
    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim) as ui:
        port = int(ui.base.rsplit(":", 1)[1])
        loading = socket.create_connection(("127.0.0.1", port), timeout=WAIT_S)
        loading.sendall(b"GET /?token=" + ui.token.encode() + b" HTTP/1.1\r\n")  # under way
        time.sleep(0.2)  # host time: the server has read it (the order matters, not the figure)
        idle = [socket.create_connection(("127.0.0.1", port), timeout=WAIT_S) for _ in range(64)]
        time.sleep(0.2)
        loading.sendall(b"Host: 127.0.0.1\r\n\r\n")
        try:
            status = loading.recv(64).split(b"\r\n", 1)[0]
        except OSError as e:
            status = repr(e).encode()
        for c in idle + [loading]:
            c.close()
    assert status.startswith(b"HTTP/1.1 200"), status


WRITE_LIMIT = 256 * 1024  # aiohttp's WebSocket writer waits for the peer to drain past this


def _frame(n: int) -> int:
    """A server frame's bytes on the wire for a text of n bytes (unmasked)."""
    return n + (2 if n < 126 else 4 if n < 65536 else 10)


def upgrade(s, ui):
    """A WebSocket's opening handshake on the raw socket s, to the page's
    own address, read up to the end of the server's answer (byte by byte:
    what follows is the tab's)."""
    port = int(ui.base.rsplit(":", 1)[1])
    key = base64.b64encode(os.urandom(16)).decode()
    s.sendall((f"GET /ws?token={ui.token} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nOrigin: {ui.base}\r\n"
               f"Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
               f"Sec-WebSocket-Version: 13\r\n\r\n").encode())
    head = b""
    while b"\r\n\r\n" not in head:
        head += s.recv(1)
    assert b" 101 " in head.split(b"\r\n")[0], head[:200]


def _stuck_tab(ui):
    """A tab on a raw socket with a small receive buffer: it reads its
    hello and then nothing more. (socket, the hello frame's bytes)."""
    port = int(ui.base.rsplit(":", 1)[1])
    s = socket.socket()
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    s.settimeout(WAIT_S)
    s.connect(("127.0.0.1", port))
    upgrade(s, ui)
    first = s.recv(2)
    n, size = first[1] & 127, 2
    if n == 126:
        n, size = int.from_bytes(s.recv(2), "big"), 4
    body = b""
    while len(body) < n:
        body += s.recv(n - len(body))
    assert json.loads(body)["type"] == "hello", body
    return s, size + n


def _cut_off(s) -> bool:
    """Whether the server aborted the stuck tab: its socket reset, or ended
    once what it buffered is read. WAIT_S a guard only: one not cut off
    stays open, or is still being told what the others are."""
    s.settimeout(WAIT_S)
    deadline = time.monotonic() + WAIT_S
    try:
        while s.recv(65536):
            if time.monotonic() > deadline:
                return False
        return True
    except ConnectionResetError:
        return True
    except OSError:
        return False


async def _stuck_and_new_tab(ui, sim):
    async with aiohttp.ClientSession() as s:
        async with s.ws_connect(_ws_url(ui), headers={"Origin": ui.base}) as driver:
            assert json.loads((await driver.receive(timeout=WAIT_S)).data)["type"] == "hello"
            stuck, told = _stuck_tab(ui)  # what aiohttp's writer counts toward WRITE_LIMIT for it
            await driver.receive(timeout=WAIT_S)  # the driver's hello again, as the stuck tab opened
            answers = {}

            async def read():  # every broadcast the driver hears, the stuck tab is sent too
                nonlocal told
                while (msg := await driver.receive()).type == aiohttp.WSMsgType.TEXT:
                    said = json.loads(msg.data)
                    if said.get("type") != "hello":  # the driver's own role; the stuck tab's is counted below
                        told += _frame(len(msg.data.encode()))
                        told = 0 if told > WRITE_LIMIT else told  # the writer waited to drain, and counts anew
                    if said.get("type") in ("result", "error"):
                        answers[said.get("tag")] = said

            reader = asyncio.ensure_future(read())

            async def run(argv, tag):
                await driver.send_str(json.dumps({"op": "run", "argv": argv, "tag": tag}))
                deadline = time.monotonic() + WAIT_S
                while tag not in answers:
                    assert time.monotonic() < deadline, f"no answer to {tag}"
                    await asyncio.sleep(0.002)
                return answers[tag]

            for i in range(40):  # ~60 KB each, 2.4 MB in all: the stuck tab's buffers fill
                await run(["config"] + ["x" * 1000] * 60, f"f{i}")
            assert (await run(["wheel", "1", "run", "--speed", "180"], "spin"))["code"] == 0
            # Near the writer's limit: a new tab's hello to the stuck one is what crosses it.
            i = 0
            while WRITE_LIMIT - told > 8000:
                room = WRITE_LIMIT - told
                words = max(0, min(60, (room - 8000) // 2005))
                await run(["config", "y" * 1000] + ["z" * 1000] * words, f"n{i}")
                i += 1
            while abs(sim.state(1)["velocity"]) < 30:
                await asyncio.sleep(0.01)
            for _ in range(60):  # a tab opened, as a reload does, until one is not told hello
                new = await s.ws_connect(_ws_url(ui), headers={"Origin": ui.base})
                try:  # a hello held behind the stuck tab never comes; a loaded PC's comes late
                    hello = await new.receive(timeout=WAIT_S)
                except asyncio.TimeoutError:
                    break
                assert json.loads(hello.data)["type"] == "hello", hello
                told += _frame(len(hello.data.encode()))  # the stuck tab's hello, as long as this one's
                if told > WRITE_LIMIT:
                    break  # the writer's limit crossed, and the new tab told hello all the same
                await new.close()
            t0_ms = sim.clock_s() * 1000.0
            await new.send_str(json.dumps({"op": "stopall", "mode": "release"}))
            deadline = time.monotonic() + WAIT_S
            while (coasted := sim.state(1)["coasted_ms"]) < t0_ms and time.monotonic() < deadline:
                await asyncio.sleep(0.002)
            stopped = coasted >= t0_ms
            await driver.send_str(json.dumps({"op": "stopall", "mode": "release"}))
            cut = _cut_off(stuck)
            stuck.close()
            await new.close()
            reader.cancel()
            return stopped, coasted - t0_ms, cut


def test_a_tab_that_does_not_read_holds_no_other_tab():
    """A tab that stopped reading once its buffers were full held the
    hello a new tab's opening sends every tab (aiohttp's writer waited for
    it to drain): the new tab never reached its loop, and its STOP ALL was
    never read. Now each tab's messages go through an outbox of its own and
    one that leaves OUTBOX_MAX bytes unread is aborted, said on stderr."""
    with Simulator(ids=[1, 2]) as sim, UiProcess(sim) as ui:
        stopped, ms, cut = asyncio.run(_stuck_and_new_tab(ui, sim))
        code, err = ui.stop()
    assert stopped, "the new tab's STOP ALL did not reach the wire"
    assert ms <= PREEMPTED_MS, ms
    assert cut, "the stuck tab was not cut off"
    assert "is cut off" in err and "unread" in err, err[:2000]
    assert code == 0 and "Traceback" not in err, err[:2000]
