"""servoctl ui's bus thread (ui/worker.py) without a browser: what the
page's requests do on servo_sim, judged on the simulator's state."""
import time

import pytest

from servoctl.protocol import Bus
from servoctl.sim import Simulator
from servoctl.ui.worker import Worker


def _worker(sim, said):
    argv = ["--port", sim.url, "--sim-control", str(sim.control_port)]
    return Worker(sim.bus(), argv, said.append)


def test_stop_all_stops_a_servo_the_last_scan_did_not_list():
    """Servos left out of the last scan (none yet, a shared ID, a new ID
    given since) are stopped too: stop-all is the user's emergency stop."""
    with Simulator(ids=[1, 2], fast=True) as sim:
        said = []
        w = _worker(sim, said)
        assert w.run(["wheel", "2", "run", "--speed", "180"])["code"] == 0
        sim.wait_until(lambda: abs(sim.state(2)["velocity"]) > 100, timeout_s=10)
        w.known = [1]  # a scan that missed servo 2
        w.stop_all("damping")
        sim.wait_until(lambda: abs(sim.state(2)["velocity"]) < 2, timeout_s=5)
        assert said[-1]["type"] == "stopped" and not said[-1]["failed"], said[-1]


def test_stop_all_stops_a_servo_left_at_another_baud_rate():
    """A baud change from the page moves the host's rate with the servo
    changed (the simulator's, on its control port): the others, left at
    the old rate, were deaf to STOP ALL and turned on. The broadcast goes
    out at every rate item 36 has, and the host's rate comes back."""
    with Simulator(ids=[1, 2], fast=True) as sim:
        said = []
        w = _worker(sim, said)
        for servo_id in (1, 2):
            assert w.run(["wheel", str(servo_id), "run", "--speed", "180"])["code"] == 0
        changed = w.run(["config", "set", "1", "baud", "1000000"])
        assert changed["code"] == 0 and w.bus.serial.baudrate == 1000000, changed
        sim.wait_until(lambda: all(abs(sim.state(i)["velocity"]) > 100 for i in (1, 2)), timeout_s=10)
        w.known = [1, 2]
        asked_ms = sim.clock_s() * 1000
        w.stop_all("release")
        sim.wait_until(lambda: all(abs(sim.state(i)["velocity"]) < 2 for i in (1, 2)), timeout_s=5)
        assert w.bus.serial.baudrate == 1000000  # the host's rate as it was
        assert said[-1]["type"] == "stopped"
        # Servo 2, at 115 200, before servo 1's answer at the host's rate was
        # waited for: the sweep comes first (it came after, 1-1.7 s late).
        took_ms = sim.state(2)["coasted_ms"] - asked_ms
        assert 0 < took_ms < 100, took_ms
        assert any("stops if it speaks another" in f for f in said[-1]["failed"]) or not said[-1]["failed"]


def test_a_rate_the_port_refuses_ends_no_stop_all(monkeypatch):
    """A port that refuses a rate (a driver without 250 000): STOP ALL
    raised there, swept no lower rate and stopped no servo; now the rate
    is said and the sweep and the servos' own stops go on."""
    from servoctl import link_rate
    with Simulator(ids=[1, 2], fast=True) as sim:
        said = []
        w = _worker(sim, said)
        for servo_id in (1, 2):
            assert w.run(["wheel", str(servo_id), "run", "--speed", "180"])["code"] == 0
        # The host follows servo 2 to 9600; servo 1, at 115 200, is below
        # the refused rate in the sweep.
        assert w.run(["config", "set", "2", "baud", "9600"])["code"] == 0 and w.bus.serial.baudrate == 9600
        set_rate = link_rate.set_rate

        def refusing(bus, sim_control, rate):
            if rate == 250000:
                raise OSError("the driver refuses 250000 baud")
            set_rate(bus, sim_control, rate)
        monkeypatch.setattr(link_rate, "set_rate", refusing)
        w.known = [1, 2]
        w.stop_all("release")
        sim.wait_until(lambda: all(abs(sim.state(i)["velocity"]) < 2 for i in (1, 2)), timeout_s=5)
        assert said[-1]["type"] == "stopped" and w.bus.serial.baudrate == 9600
        assert any("250000 baud: the driver refuses" in f for f in said[-1]["failed"]), said[-1]


def test_the_bus_thread_outlives_a_lost_link_and_a_bad_plot_request():
    """A link that fails while several servos are plotted (a USB adapter
    pulled), or a plot of ID 300, is told to the page; the thread that
    runs stop-all goes on (it died, and every request after was lost)."""
    with Simulator(ids=[1, 2], fast=True) as sim:
        said = []
        w = Worker(Bus(sim.url, timeout=0.05), [], said.append)
        w.start()
        try:
            w.submit(w.plot, [1, 300])
            _heard(said, lambda m: m["type"] == "error" and "not 300" in m["text"])
            w.submit(w.plot, [1, 2])
            _heard(said, lambda m: m["type"] == "samples")
            sim.stop()  # the bus's far end closes
            _heard(said, lambda m: m["type"] == "error" and "LinkError" in m["text"])
            assert w.thread.is_alive()
        finally:
            w.stop()
        assert not w.thread.is_alive()


def test_a_jog_moves_a_step_from_where_the_servo_is_and_no_farther():
    """The Motion view's slider stood at 0 deg whatever the servo's angle:
    a nudge threw a servo resting at 60 deg to 1 deg at full speed. The
    bus thread reads the angle and takes a jog within a slider's step of
    it only; the page hears the angle after it."""
    with Simulator(ids=[1], fast=True) as sim:
        said = []
        w = _worker(sim, said)
        assert w.run(["config", "set", "1", "soft_start_on", "0"])["code"] == 0
        assert w.run(["move", "1", "60", "--velocity", "200", "--wait"])["code"] == 0
        far = w.jog(1, 1.0, 0, "t")
        assert far["code"] == 2 and "a jog moves 1.5 deg at most from where the servo is: servo 1 is at 60" \
            in far["err"], far
        sim.sleep(0.3)  # a jog to 1 deg sent would have the horn tens of degrees on by now
        assert abs(sim.state(1)["angle"] - 60) < 0.5
        near = w.jog(1, 61.0, 0, "t")
        assert near["code"] == 0 and near["argv"] == ["move", "1", "61", "--interval", "200", "--wait"], near
        assert abs(sim.state(1)["angle"] - 61) < 0.5
        assert abs(w.angle(1) - 61) < 0.5 and said[-1]["type"] == "angle" and said[-1]["id"] == 1
        assert w.jog(7, 0.0, 0)["code"] == 3  # no servo 7: said, nothing sent to move
        # A jog asked before a STOP ALL the page had not heard of (a drag in one tab, the
        # stop from another) is not run: it moved the servo again after the stop.
        w.stop_now("release")
        w.preempt.clear()  # as the bus thread does before it runs the stop
        w.stop_all("release")
        assert said[-1]["type"] == "stopped" and said[-1]["stops"] == 1
        late = w.jog(1, 61.5, 0, "t")
        assert late["code"] == 130 and "STOP ALL came after this jog was asked" in late["err"], late
        again = w.jog(1, 61.5, w.stops, "t")
        assert again["code"] == 0, again


def test_the_page_names_files_in_its_folder_only(tmp_path):
    """With the token, config save/load, backup and
    restore read and wrote any file the server's user could. Now only
    files in the ui's folder (--files DIR); the refusal says so."""
    (tmp_path / "bench").mkdir()
    with Simulator(ids=[1], fast=True) as sim:
        said = []
        w = Worker(sim.bus(), ["--port", sim.url], said.append, files=tmp_path / "bench")
        for argv in (["config", "save", "1", "../escape.json"], ["backup", str(tmp_path / "escape.json")],
                     ["restore", "/etc/passwd"], ["config", "diff", "1", "/etc/passwd"]):
            done = w.run(argv)
            assert done["code"] == 2 and f"the page names files in {tmp_path / 'bench'} only" in done["err"], done
        assert not (tmp_path / "escape.json").exists()
        assert w.run(["config", "save", "1", "servo.json"])["code"] == 0
        assert (tmp_path / "bench" / "servo.json").exists()


def _heard(said, what):
    deadline = time.monotonic() + 10  # host time: a bound on failure only
    while not any(what(m) for m in list(said)):
        assert time.monotonic() < deadline, said[-3:]
        time.sleep(0.01)


def test_the_queue_is_bounded_and_a_full_one_refuses_with_a_message():
    """The page's actions queued without bound (50 000 of them held STOP
    ALL back 4.6 s, each answered "not run" before it)."""
    from servoctl.ui import worker as ui_worker

    with Simulator(ids=[1], fast=True) as sim:
        w = _worker(sim, [])
        for i in range(ui_worker.QUEUE_MAX):
            w.submit(w.run, ["ping", "1"], i)
        with pytest.raises(ui_worker.QueueFull, match="actions are waiting for the bus: this one is refused"):
            w.submit(w.run, ["ping", "1"], "one too many")
        w.preempt.close()


def test_a_burst_of_stop_all_clicks_puts_few_stops_on_the_wire():
    """Each click wrote a broadcast: a page that floods STOP ALL filled the
    wire (and blocked the server's thread on a full socket)."""
    with Simulator(ids=[1], fast=True) as sim:
        w = _worker(sim, [])
        for _ in range(2000):
            w.preempt.broadcast_stop("release")
        sim.sleep(0.3)
        w.preempt.close()
        runs = [line.split() for line in sim.control("wire 1024").splitlines() if line.strip() not in ("", "end")]
        sent = sum(int(r[2]) for r in runs if r[3] == "host")
        assert 0 < sent <= 50 * 9, runs  # a stop frame is 9 bytes; 2000 of them without the limit


def test_a_file_written_into_a_missing_folder_is_refused_before_the_command_runs(tmp_path):
    """config save into a folder that is not there said "saved", then a
    bare errno; now refused first, the folder named."""
    with Simulator(ids=[1], fast=True) as sim:
        said = []
        w = Worker(sim.bus(), ["--port", sim.url], said.append, files=tmp_path)
        for argv, name in ((["config", "save", "1", "nosub/deeper/servo.json"], "nosub/deeper/servo.json"),
                           (["backup", "nosub/bus.json"], "nosub/bus.json")):
            done = w.run(argv)
            assert done["code"] == 2 and "saved" not in done["out"], done
            assert f"ui: {name!r} is not written: no such folder: nosub in {tmp_path}" in done["err"], done
            assert "Errno" not in done["err"], done
        (tmp_path / "nosub").mkdir()
        assert w.run(["backup", "nosub/bus.json"])["code"] == 0
        assert (tmp_path / "nosub" / "bus.json").exists()
        w.preempt.close()


def test_the_live_table_refreshes_a_plotted_servo():
    """The table skipped every plotted ID: a plotted servo that went silent
    stayed "answering" (docs/ui.md: every 3 s while plotting)."""
    with Simulator(ids=[1, 2], fast=True) as sim:
        said = []
        w = _worker(sim, said)
        w.known = [1, 2]
        w.plot([1])
        assert sim.control("unplug 1 1").strip() == "ok"
        w.table()
        rows = {r["id"]: r for r in said[-1]["rows"]}
        assert said[-1]["type"] == "table" and set(rows) == {1, 2}, said[-1]
        assert rows[1].get("gone") and not rows[2].get("gone"), rows
        w.preempt.close()


def test_a_silent_servo_s_items_are_said_once_not_blamed_on_its_firmware():
    """An unplugged servo's Read every item took a wait for each item
    (11 s) and said each was "not on this servo's firmware"."""
    with Simulator(ids=[1, 2], fast=True) as sim:
        said = []
        w = _worker(sim, said)
        w.items(1)
        assert said[-1]["items"] and not said[-1].get("silent"), said[-1]
        assert sim.control("unplug 1 2").strip() == "ok"
        t0 = w.bus.clock()
        w.items(2)
        took_s = w.bus.clock() - t0  # the simulator's clock
        heard = said[-1]
        assert heard["type"] == "items" and heard["items"] == [], heard
        assert "servo 2 does not answer" in heard["silent"] and "firmware" not in heard["silent"], heard
        assert took_s < 1.0, took_s  # one wait for an answer, not one for each of ~30 items
        w.preempt.close()


def test_stop_all_answers_every_request_it_drops():
    """A queued scan, Read every item or plot dropped by STOP ALL had no
    answer: the page said "scanning…" for ever."""
    NOT_RUN = "servoctl ui: not run: stop-all came first"
    with Simulator(ids=[1], fast=True) as sim:
        said = []
        w = _worker(sim, said)
        w.known = [1]
        w.submit(w.run, ["ping", "1"], 1)
        w.submit(w.scan, False, 2)
        w.submit(w.items, 1, 3)
        w.submit(w.plot, [1], 4)
        w.stop_now("release")  # the click: what is queued now is answered "not run"
        w.submit(w.run, ["ping", "1"], 5)  # asked after it: runs after the stop
        w.preempt.clear()  # as the bus thread does before each job, then runs the stop
        w.stop_all("release")
        answers = {m.get("tag"): m for m in said if m["type"] in ("result", "error")}
        assert 5 not in answers and len(w.jobs) == 1, answers
        assert answers[1]["type"] == "result" and answers[1]["err"] == NOT_RUN, answers
        for tag, op in ((2, "scan"), (3, "items"), (4, "plot")):
            assert answers[tag]["op"] == op and answers[tag]["text"] == NOT_RUN, answers
        w.preempt.close()


def test_an_update_stop_all_cuts_short_says_its_servo_is_left_in_its_bootloader(tmp_path):
    """The box said "interrupted by stop-all" alone; the servo waits in its
    bootloader, and the user must know to run the update again."""
    from servoctl import image as img

    (tmp_path / "fw.img").write_bytes(img.build(bytes(range(256)) * 6, 0x0042, img.BOARDS["host_sim"]))
    with Simulator(ids=[1], fast=True) as sim:
        said = []

        def publish(msg):  # STOP ALL as the first block's progress is told (on the bus thread)
            said.append(msg)
            if msg["type"] == "progress":
                w.preempt.interrupt("stop-all")
        w = Worker(sim.bus(), ["--port", sim.url], publish, files=tmp_path)
        done = w.run(["update", "1", "fw.img"])
        assert done["code"] == 130 and "servoctl: interrupted by stop-all" in done["err"], done
        assert "a servo it had switched to its bootloader is left there" in done["err"], done
        assert sim.state(1)["mode"] != "app"
        w.preempt.close()
