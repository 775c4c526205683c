"""A calibrate or tune that does not finish leaves each stored item it
wrote as it was before (tools/servoctl/putback.py): Ctrl-C on the command
line at each of calibrate's steps, the ui's STOP ALL and its tab closing
during the current's binary search, and a servo gone mid-search (then the
exit code is 5 and the message names the item, what it holds and what it
should hold). Before, item 91 was left at the search's midpoint, in flash:
the servo read 0 A while it drew current and its current protections were
blind. Time is the simulator's."""
import asyncio
import json
import signal
import subprocess
import time

import pytest

from servoctl import protocol
from servoctl.cli import main
from servoctl.putback import PutBack
from servoctl.servo import Servo
from servoctl.sim import Simulator

from ..launchers import servoctl_child
from ..ui_launch import UiProcess
from .conftest import finish

AMP_ZERO = 25
ITEMS = ("current_zero", "gear_ratio", "encoder_zero")


def _start(tmp_path, paced=True):
    """Paced (docs/simulator.md, "Running ahead"): calibrate's polls (come
    to rest, the return) see the servo where it is on the simulated clock
    however late a loaded PC runs them, so the count of its sleeps is the
    same on every run. paced=False: a real-time simulator, for a command
    line or ui that does not pace it."""
    sim = Simulator(paced=paced, state_dir=str(tmp_path / "state")).start()
    for line in ("magnet 30", "swapleads 1", f"ampzero {AMP_ZERO}"):
        assert sim.control(line).strip() == "ok", line
    return sim


def _items(sim, servo_id=1):
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, servo_id)
        return {name: s.read(name) for name in ITEMS}


def _cut_at(monkeypatch, sim, after: int, what=None):
    """Bus.sleep raises KeyboardInterrupt (a Ctrl-C) at its after-th call,
    or calls what() there and goes on."""
    calls = {"n": 0}
    real = protocol.Bus.sleep

    def sleep(bus, seconds):
        calls["n"] += 1
        if calls["n"] == after:
            if what is None:
                raise KeyboardInterrupt
            what()
        real(bus, seconds)
    monkeypatch.setattr(protocol.Bus, "sleep", sleep)
    return calls


# Sleeps of calibrate: 12 of the search (one a step), the store's, then the
# pushes' and their come_to_rest's; the gear ratio is written after the first
# push (reversed leads), the zero after the return.
@pytest.mark.parametrize("after", [3, 12, 20, 30, 60])
def test_ctrl_c_at_any_step_of_calibrate_puts_every_item_back(tmp_path, monkeypatch, capsys, after):
    sim = _start(tmp_path)
    try:
        before = _items(sim)
        calls = _cut_at(monkeypatch, sim, after)
        code = main(["--port", sim.url, "calibrate", "1"], clock=sim.clock_s)
        assert calls["n"] >= after, "calibrate ended before the Ctrl-C"
        err = capsys.readouterr().err
        assert code == 130, err
        assert "calibrate stopped part-way (interrupted): put back as they were" in err, err
        monkeypatch.undo()
        assert _items(sim) == before, err
    finally:
        finish(sim, [1])


def test_a_calibrate_that_finishes_keeps_what_it_found(tmp_path, monkeypatch, capsys):
    sim = _start(tmp_path)
    try:
        calls = _cut_at(monkeypatch, sim, 10 ** 6)
        assert main(["--port", sim.url, "calibrate", "1"], clock=sim.clock_s) == 0
        assert calls["n"] > 60  # the step counts above are within calibrate
        monkeypatch.undo()
        now = _items(sim)
        assert now["current_zero"] == AMP_ZERO and now["gear_ratio"] < 0, now
        assert "put back" not in capsys.readouterr().err
    finally:
        finish(sim, [1])


def test_a_servo_gone_mid_search_is_said_with_the_item_and_exit_5(tmp_path, monkeypatch, capsys):
    sim = _start(tmp_path)
    try:
        before = _items(sim)["current_zero"]
        _cut_at(monkeypatch, sim, 4, lambda: sim.control("unplug 1 1"))
        code = main(["--port", sim.url, "calibrate", "1"], clock=sim.clock_s)
        err = capsys.readouterr().err
        assert code == 5, err
        assert "could NOT put back" in err and "current_zero (item 91) holds" in err, err
        assert f"it should hold {before}" in err and f"servoctl config set 1 current_zero {before}" in err, err
        monkeypatch.undo()
        assert sim.control("unplug 0 1").strip() == "ok"
        left = _items(sim)["current_zero"]
        assert left != before and f"holds {left} " in err, (left, err)  # what it said it holds
    finally:
        finish(sim, [1])


def _run_clock(sim, until, limit_s: float):
    """Moves a paced simulator's clock on 5 ms at a time, each step a host
    moment apart (about real time on an idle PC, slower on a loaded one),
    until until() is true; AssertionError after limit_s of simulated time.
    Between calls its clock stands still, however late the host is."""
    start = sim.clock_s()
    while not until():
        assert sim.clock_s() - start < limit_s, f"not within {limit_s} s of simulated time"
        sim.sleep(0.005)
        time.sleep(0.002)


@pytest.mark.parametrize("how", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_ctrl_c_on_the_command_line_puts_item_91_back(tmp_path, how):
    """A real SIGINT to `servoctl calibrate`, or a SIGTERM or SIGHUP (a
    kill, a closed terminal) taken as one: exit 130, item 91 as it was.
    The simulator is paced by the test, not by the command: its clock
    moves only while the test moves it, so the signal lands in the search
    (after its third write of item 91) however late a loaded PC delivers
    it; on a real-time simulator the command could end first."""
    sim = _start(tmp_path)
    proc = None
    try:
        before = _items(sim)
        saves = sim.state(1)["saves"]
        # SIGINT as at a terminal, even where the tests run in a background
        # job (its processes start with SIGINT ignored).
        proc = servoctl_child("--port", sim.url, "--sim-control", str(sim.control_port), "calibrate", "1",
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        # The search under way: each of its steps writes item 91 (a save).
        _run_clock(sim, lambda: sim.state(1)["saves"] >= saves + 3 or proc.poll() is not None, 60.0)
        assert proc.poll() is None, proc.communicate()
        assert "calibrating" in proc.stdout.readline()
        proc.send_signal(how)
        _run_clock(sim, lambda: proc.poll() is not None, 10.0)  # the put-back's writes
        out, err = proc.communicate(timeout=30)
        assert proc.returncode == 130, err
        assert "put back as they were: current_zero" in err, err
        assert how == signal.SIGINT or f"interrupted by {how.name})" in err, err
        assert _items(sim) == before, err
    finally:
        if proc is not None and proc.poll() is None:
            proc.kill()
            proc.wait()
        finish(sim, [1])


async def _ui_cut(ui, sim, how: str):
    aiohttp = pytest.importorskip("aiohttp")
    url = ui.base.replace("http", "ws", 1) + "/ws?token=" + ui.token
    async with aiohttp.ClientSession() as s:
        ws = await s.ws_connect(url, headers={"Origin": ui.base})
        await ws.send_str(json.dumps({"op": "scan", "tag": 1}))
        await ws.send_str(json.dumps({"op": "run", "argv": ["calibrate", "1"], "tag": 2}))
        heard = []
        deadline = time.monotonic() + 30
        while not any(m.get("type") == "line" and m.get("tag") == 2 for m in heard):
            assert time.monotonic() < deadline, heard[-3:]
            heard.append(json.loads((await ws.receive(timeout=30)).data))
        sim.sleep(0.25)  # the search under way
        if how == "close":
            await ws.close()
            sim.sleep(1.0)
            return None
        await ws.send_str(json.dumps({"op": "stopall", "mode": "release"}))
        while not (heard and heard[-1].get("type") == "result" and heard[-1].get("tag") == 2):
            assert time.monotonic() < deadline, heard[-3:]
            heard.append(json.loads((await ws.receive(timeout=30)).data))
        await ws.close()
        return heard[-1]


@pytest.mark.parametrize("how", ["stopall", "close"])
def test_the_uis_stop_all_or_closed_tab_puts_item_91_back(tmp_path, how):
    sim = _start(tmp_path, paced=False)
    try:
        before = _items(sim)
        with UiProcess(sim) as ui:
            said = asyncio.run(_ui_cut(ui, sim, how))
            code, err = ui.stop()
        assert code == 0 and "Traceback" not in err, err
        if said is not None:
            assert said["code"] == 130, said
            assert "calibrate stopped part-way (interrupted by stop-all): put back" in said["err"], said
        assert _items(sim) == before
    finally:
        finish(sim, [1])


def test_tunes_items_cut_before_their_check_are_put_back(tmp_path):
    """tune writes the drive and gain items, then checks a step: a Ctrl-C
    or STOP ALL there puts back the set the servo had (in an order that
    keeps the loop stable at each write)."""
    sim = _start(tmp_path)
    try:
        with sim.bus(timeout=0.2) as bus:
            s = Servo(bus, 1)
            names = ("gain_kp", "gain_ki", "gain_kd")
            before = {n: s.read(n) for n in names}
            with pytest.raises(KeyboardInterrupt):
                with PutBack(s, "tune") as kept:
                    kept.write_drive({n: v + 1 for n, v in before.items()})
                    assert {n: s.read(n) for n in names} != before
                    raise KeyboardInterrupt
            assert {n: s.read(n) for n in names} == before
    finally:
        finish(sim, [1])
