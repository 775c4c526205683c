"""servoctl ui under a burst of small messages from one tab (docs/ui.md, "A
tab that floods"): another tab's STOP ALL is still taken within
PREEMPTED_MS of the simulator's clock; the bursting tab is told its
messages over the rate are refused, then cut off; a STOP ALL sent behind
a burst, over the rate, is still taken. Before, 3 000 to 20 000 messages
of a few bytes, sent in one write, were each taken without the server's
loop turning once: STOP ALL waited 0.1-2.9 s behind them."""
import asyncio
import socket
import threading

import pytest

from servoctl.sim import Simulator
from ..ui_launch import UiProcess
from ..ui_stop_bench import Page
from .test_ui_flood import PREEMPTED_MS, _spin, _stop_ms, _ws_url, upgrade

aiohttp = pytest.importorskip("aiohttp")

BURST = 20_000  # messages in one write: 300 KB


def _raw_tab(ui):
    """A tab's WebSocket on a plain socket: a burst is one sendall."""
    s = socket.create_connection(("127.0.0.1", int(ui.base.rsplit(":", 1)[1])), timeout=10)
    upgrade(s, ui)
    return s


def _frame(payload: bytes) -> bytes:
    """One masked text frame of under 126 bytes, as a browser sends it."""
    mask = b"\x01\x02\x03\x04"
    return bytes([0x81, 0x80 | len(payload)]) + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload))


def _reader(s, heard: list):
    """Reads what the server tells the raw tab until it is closed or cut off."""
    s.settimeout(30)
    try:
        while chunk := s.recv(1 << 16):
            heard.append(chunk)
    except OSError:
        pass
    heard.append(None)  # its end


async def _burst_then_stop(ui, sim, payloads, stop_from_burst: bool):
    async with aiohttp.ClientSession() as session:
        async with session.ws_connect(_ws_url(ui), headers={"Origin": ui.base}, max_msg_size=0) as driver, \
                session.ws_connect(_ws_url(ui), headers={"Origin": ui.base}) as watcher:
            page = Page(driver, sim)
            await page.until(lambda m: m["type"] == "hello")
            await page.send({"op": "scan"})
            await page.until(lambda m: m["type"] == "scan")
            await _spin(page, sim)
            raw, heard = _raw_tab(ui), []
            reading = threading.Thread(target=_reader, args=(raw, heard), daemon=True)
            reading.start()
            try:
                if stop_from_burst:  # the burst's last message is STOP ALL
                    t0_ms = sim.clock_s() * 1000.0
                    raw.sendall(b"".join(_frame(p) for p in payloads))
                    while (coasted := sim.state(1)["coasted_ms"]) < t0_ms:
                        await page.sim_sleep(0.002)
                    ms = coasted - t0_ms
                else:
                    raw.sendall(b"".join(_frame(p) for p in payloads))
                    await asyncio.sleep(0.05)  # host time: the burst is in the server's buffers
                    ms = await _stop_ms(Page(watcher, sim), sim)
                await page.sim_sleep(1.0)
            finally:
                raw.close()
                reading.join(timeout=10)
            return ms, b"".join(c for c in heard if c)


def test_another_tabs_stop_all_is_taken_during_a_burst():
    with Simulator(ids=[1, 2]) as sim, UiProcess(sim) as ui:
        ms, told = asyncio.run(_burst_then_stop(ui, sim, [b"not json{"] * BURST, False))
        code, err = ui.stop()
    print(f"STOP ALL behind a burst of {BURST}: {ms:.1f} ms")
    assert ms <= PREEMPTED_MS, ms
    assert b"messages a second: refused, not run" in told, told[-400:]
    assert "is cut off: 2000 messages over the 100 a second a tab may send" in err, err[:2000]
    assert code == 0 and "Traceback" not in err, err[:2000]


def test_a_stop_all_behind_a_burst_over_the_rate_is_taken():
    payloads = [b"not json{"] * 500 + [b'{"op": "stopall", "mode": "release"}']
    with Simulator(ids=[1, 2]) as sim, UiProcess(sim) as ui:
        ms, _ = asyncio.run(_burst_then_stop(ui, sim, payloads, True))
        code, err = ui.stop()
    assert ms <= PREEMPTED_MS, ms
    assert "is cut off" not in err, err[:2000]
    assert code == 0 and "Traceback" not in err, err[:2000]
