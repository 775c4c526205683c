"""servoctl says what really happened, in one line, with an exit code
(0 done, 1 refused or not arrived, 2 usage, 3 no reply, 4 link, 130
interrupted): every case a new user met."""
import json
import os
import signal
import subprocess
import sys
import threading
import time

import pytest

from servoctl import __version__
from servoctl.cli import main

from ..launchers import servoctl_child

TOOLS = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(sim, capsys, *args):
    rc = main(["--port", sim.url, *args], clock=sim.clock_s)
    out = capsys.readouterr()
    assert "Traceback" not in out.err
    assert len(out.err.strip().splitlines()) <= 1, out.err
    return rc, out.out, out.err


@pytest.fixture
def ready(sim, capsys):
    assert run(sim, capsys, "config", "set", "1", "soft_start_on", "0")[0] == 0
    return sim


def test_a_blocked_move_fails_and_says_so(ready, capsys):
    ready.control("stop 20")
    rc, out, err = run(ready, capsys, "move", "1", "60", "--interval", "500", "--wait")
    assert rc == 1 and "blocked" in err and "stalled" in err, err
    ready.control("stop off")


def test_a_move_without_power_fails(ready, capsys):
    rc, _, err = run(ready, capsys, "move", "1", "90", "--power", "1mW", "--wait")
    assert rc == 1 and "servo 1:" in err and ("stalled" in err or "did not arrive" in err), err


def test_a_move_refused_by_a_protection_fails(ready, capsys):
    ready.control("soak 100")
    ready.sleep(0.3)
    rc, _, err = run(ready, capsys, "move", "1", "0", "--wait")
    assert rc == 1 and "refused" in err and "over_temperature" in err, err
    ready.control("soak 25")


def test_a_move_past_the_limits_is_refused_before_sending(ready, capsys):
    rc, _, err = run(ready, capsys, "move", "1", "170", "--interval", "300", "--wait")
    assert rc == 2 and "limits its angle to -135.0 deg..135.0 deg" in err and "170.0 deg is outside" in err, err
    ready.sleep(0.4)
    assert abs(ready.state(1)["angle"]) < 0.5


def test_the_wait_follows_the_plan(ready, capsys):
    rc, out, _ = run(ready, capsys, "move", "1", "30", "--interval", "2500", "--wait")
    assert rc == 0 and "planned 2500 ms" in out, out
    took = float(out.split(" after ")[1].split(" ms")[0])
    assert 2400 < took < 3500, out
    rc, _, err = run(ready, capsys, "move", "1", "-30", "--interval", "3000", "--wait", "--timeout-s", "0.5")
    assert rc == 1 and "did not arrive within 0.5 s" in err, err


@pytest.mark.parametrize("argv", [["move", "7", "30"], ["stop", "9"], ["damping", "9"],
                                  ["wheel", "9", "run"], ["origin", "9"]])
def test_a_command_to_an_absent_servo_fails(sim, capsys, argv):
    rc, _, err = run(sim, capsys, *argv)
    assert rc == 3 and "did not answer" in err, err


def test_origin_refused_while_holding_fails(ready, capsys):
    assert run(ready, capsys, "move", "1", "10", "--interval", "100", "--wait")[0] == 0
    rc, _, err = run(ready, capsys, "origin", "1")
    assert rc == 1 and "release it first" in err, err


@pytest.mark.parametrize("value", ["abc", "2.5X", "true"])
def test_a_bad_config_value_is_one_line(sim, capsys, value):
    rc, _, err = run(sim, capsys, "config", "set", "1", "stall_power", value)
    assert rc == 2 and f"not {value!r}" in err, err


def test_a_bad_angle_is_one_line(sim, capsys):
    with pytest.raises(SystemExit) as e:
        main(["--port", sim.url, "move", "1", "nan"])
    assert e.value.code == 2
    assert "not a finite number" in capsys.readouterr().err


def test_config_files_that_cannot_be_loaded(sim, capsys, tmp_path):
    rc, _, err = run(sim, capsys, "config", "load", "1", str(tmp_path / "missing.json"))
    assert rc == 2 and "cannot read" in err
    bad = tmp_path / "bad.json"
    bad.write_text("{stall_power: 1")
    rc, _, err = run(sim, capsys, "config", "load", "1", str(bad))
    assert rc == 2 and "is not JSON" in err


def test_config_load_keeps_the_link_and_takes_part_of_a_file(sim, capsys, tmp_path):
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"servo_id": "5", "baud": "1000000 baud", "stall_power": "1234 mW"}))
    rc, out, _ = run(sim, capsys, "config", "load", "1", str(other))
    assert rc == 0 and "kept servo_id 1" in out, out
    assert run(sim, capsys, "config", "get", "1", "stall_power")[1] == "stall_power = 1234 mW\n"
    assert run(sim, capsys, "ping", "1")[0] == 0


def test_record_checks_where_it_writes_before_moving(ready, capsys):
    before = ready.state(1)["angle"]
    rc, _, err = run(ready, capsys, "record", "1", "60", "--out", "/nonexistent/x")
    assert rc == 2 and "not a writable folder" in err
    ready.sleep(0.2)
    assert abs(ready.state(1)["angle"] - before) < 0.5  # it did not move


def test_a_dropped_link_is_one_line(sim, capsys):
    threading.Timer(0.5, lambda: sim.process.kill()).start()
    rc, _, err = run(sim, capsys, "monitor", "1", "--every", "0.05", "--count", "100")
    assert rc == 4, err
    sim.start()  # for the fixture's final check


def test_version(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0 and capsys.readouterr().out.strip() == f"servoctl {__version__}"


def test_ctrl_c_stops_cleanly(sim):
    # Its reply time-out on the simulator's clock (--sim-control): a loaded
    # PC that holds up the simulator makes the answers late on the host's
    # clock, and servo 1's answer, arriving in servo 2's window, read as two
    # servos at ID 2.
    proc = servoctl_child("--port", sim.url, "--sim-control", str(sim.control_port), "scan",
                          "--reply-timeout", "0.05",  # 254 IDs: 12 s
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    # Interrupted once it has found servo 1 (a loaded PC may take seconds
    # to start Python); stdout ends when it exits.
    first = proc.stdout.readline()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    out = first + out
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "interrupted" in err
    # The summary is not lost.
    assert "servo 1 at 115200 baud" in out and "servo(s) found (interrupted)" in out


def test_a_full_scan_waits_about_a_second(sim, capsys):
    """A scan of 0-253 waits at most the request, the answer and 3 ms for
    each ID: about a second at 115200. How long it takes on the host is the
    host's (README: measured), not something a test can judge on a busy
    machine."""
    from servoctl.scan import reply_window_s

    assert 254 * reply_window_s(115200) < 1.1
    rc, out, _ = run(sim, capsys, "scan", "--json")
    assert rc == 0 and json.loads(out) == [{"id": 1, "baud": 115200, "mode": "application",
                                            "serials": [0x51A00001], "shared": False}]


def test_scan_refuses_ids_beyond_254(sim, capsys):
    with pytest.raises(SystemExit) as e:
        main(["--port", sim.url, "scan", "--last", "300"])
    assert e.value.code == 2 and "servo IDs are 0..254" in capsys.readouterr().err


def test_sim_stops_cleanly_on_sigterm_and_leaves_nothing(tmp_path):
    import glob
    import socket
    import tempfile

    before = set(glob.glob(os.path.join(tempfile.gettempdir(), "servo-sim-*")))
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    proc = subprocess.Popen([sys.executable, "-m", "servoctl.cli", "sim", "--tcp", str(port)],
                            cwd=TOOLS, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    assert f"socket://127.0.0.1:{port}" in line, line
    assert main(["--port", f"socket://127.0.0.1:{port}", "ping", "1"]) == 0
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=15)
    assert proc.returncode == 0 and "simulator stopped" in out, err
    assert "Traceback" not in err
    assert subprocess.run(["pgrep", "-f", f"servo_sim.*--tcp {port}"], capture_output=True).returncode == 1
    after = set(glob.glob(os.path.join(tempfile.gettempdir(), "servo-sim-*")))
    assert after <= before, f"left behind: {after - before}"


def test_servo_sim_is_found_on_the_path_outside_the_repository(tmp_path, monkeypatch):
    from servoctl import sim as simmod

    real = simmod.find_binary()
    (tmp_path / "servo_sim").symlink_to(real)
    (tmp_path / "no-repository").mkdir()
    monkeypatch.delenv("SERVO_SIM", raising=False)
    monkeypatch.chdir(tmp_path / "no-repository")  # a folder of no checkout
    monkeypatch.setenv("PATH", f"{tmp_path}{os.pathsep}{os.environ['PATH']}")
    assert simmod.find_binary() == tmp_path / "servo_sim"
    monkeypatch.setenv("PATH", "/nonexistent")
    with pytest.raises(simmod.ServoError, match="put servo_sim on the PATH"):
        simmod.find_binary()


def test_sync_broadcast_and_async_moves(sim3, capsys):
    for i in (1, 2, 3):
        assert run(sim3, capsys, "config", "set", str(i), "soft_start_on", "0")[0] == 0
    rc, out, _ = run(sim3, capsys, "sync-move", "1:30", "2:-20", "3:100", "--interval", "1500")
    assert rc == 0 and "3 servo(s) moving together" in out
    sim3.sleep(2.0)
    assert [round(sim3.state(i)["angle"]) for i in (1, 2, 3)] == [30, -20, 100]
    assert run(sim3, capsys, "broadcast-move", "10", "--interval", "300", "--ids", "1", "2", "3")[0] == 0
    sim3.sleep(0.6)
    assert [round(sim3.state(i)["angle"]) for i in (1, 2, 3)] == [10, 10, 10]
    assert run(sim3, capsys, "async", "begin")[0] == 0
    assert run(sim3, capsys, "move", "1", "-45", "--interval", "200")[0] == 0
    sim3.sleep(0.3)
    assert round(sim3.state(1)["angle"]) == 10  # buffered
    assert run(sim3, capsys, "async", "end")[0] == 0
    sim3.sleep(0.5)
    assert round(sim3.state(1)["angle"]) == -45


def test_backup_and_restore_a_whole_bus(sim3, capsys, tmp_path):
    for i in (1, 2, 3):
        run(sim3, capsys, "config", "set", str(i), "stall_power", f"{i}W")
    backup = tmp_path / "bus.json"
    rc, out, _ = run(sim3, capsys, "backup", str(backup))
    assert rc == 0 and "saved 3 servo(s) (1, 2, 3)" in out
    for i in (1, 2, 3):
        run(sim3, capsys, "config", "reset", str(i))
    rc, out, _ = run(sim3, capsys, "restore", str(backup))
    assert rc == 0 and "restored 3 servo(s)" in out
    for i in (1, 2, 3):
        assert run(sim3, capsys, "config", "get", str(i), "stall_power")[1] == f"stall_power = {1000 * i} mW\n"
    rc, _, err = run(sim3, capsys, "restore", str(tmp_path / "nothing.json"))
    assert rc == 2 and "cannot read" in err


def test_the_python_api_speaks_degrees_and_seconds(sim):
    from servoctl.protocol import Bus, ValueOutOfRange
    from servoctl.servo import Servo
    from servoctl import group

    with sim.bus() as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        result = s.move_to(90.0, duration_s=0.4, wait=True)
        assert abs(result.angle / 10 - 90.0) <= 0.5 and abs(s.position_deg() - 90.0) <= 0.5
        s.move_to(-30.5, speed_dps=200, wait=True)
        assert abs(s.position_deg() + 30.5) <= 0.5
        assert 7.0 < s.supply_v() < 7.8 and 20 < s.temperature_c() < 30
        assert s.status_names() == []
        with pytest.raises(ValueOutOfRange, match="move_to"):
            s.move(90.0, interval_ms=500)  # protocol units take whole numbers
        assert set(group.sync_monitor(bus, [1, 9])) == {1}


def test_monitor_live_views(sim3, capsys, tmp_path):
    """Servos 1 and 2 turn at 90 deg/s, opposite ways, for as long as the
    monitor samples; what it sampled is judged, not how often: each sample
    is stamped when its answer arrived (here on the simulated clock), and
    the speed is the angle's change over those stamps."""
    for i in (1, 2):
        assert run(sim3, capsys, "config", "set", str(i), "soft_start_on", "0")[0] == 0
    assert run(sim3, capsys, "wheel", "1", "run", "--speed", "90")[0] == 0
    assert run(sim3, capsys, "wheel", "2", "run", "--speed", "90", "--cw")[0] == 0
    sim3.sleep(0.3)  # up to speed
    png = tmp_path / "monitor.png"
    rc = main(["--port", sim3.url, "monitor", "1", "2", "9", "--sync", "--json", "--every", "0.05",
               "--count", "20", "--plot-file", str(png)], clock=sim3.clock_s)
    out, err = capsys.readouterr()
    assert err.splitlines() == [f"plot {png}", "servoctl: error: servo 9: no answer in its Sync Monitor slot"]
    # Servo 9 is absent: a record that says so each round, and exit 3.
    assert rc == 3
    records = [json.loads(line) for line in out.splitlines()]
    silent = [r for r in records if r.get("silent")]
    assert len(silent) == 20 and {r["id"] for r in silent} == {9} and all(r["why"] for r in silent)
    rows = [r for r in records if not r.get("silent")]
    assert {r["id"] for r in rows} == {1, 2} and len(rows) == 40
    for servo_id, sign in ((1, 1), (2, -1)):
        mine = [r for r in rows if r["id"] == servo_id]
        assert all(b["t_s"] > a["t_s"] for a, b in zip(mine, mine[1:])), "stamps out of order"
        speeds = [(b["angle_deg"] - a["angle_deg"]) / (b["t_s"] - a["t_s"]) for a, b in zip(mine, mine[1:])]
        # t_s is rounded to the millisecond, the speed is not.
        assert [r["velocity_dps"] for r in mine[1:]] == pytest.approx(speeds, rel=0.03)
        assert mine[0]["velocity_dps"] is None  # no speed from one answer (it read 0)
        assert all(sign * v > 0 for v in speeds), (servo_id, speeds)
        # A stamp is late by however long the host took to read the answer:
        # over the whole run that is within a few per cent.
        mean = (mine[-1]["angle_deg"] - mine[0]["angle_deg"]) / (mine[-1]["t_s"] - mine[0]["t_s"])
        assert abs(sign * mean - 90.0) < 9.0, (servo_id, mean)
    assert all(20 < r["temperature_c"] < 30 and 7.0 < r["voltage_v"] < 7.8 for r in rows)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rc, out, err = run(sim3, capsys, "monitor", "1", "9", "--count", "1")
    assert rc == 3 and "  9 silent: servo 9: no reply to packet 22" in out, out
    assert "servo 9: no reply" in err


def test_read_commands_speak_json(sim, capsys):
    info = json.loads(run(sim, capsys, "info", "1", "--json")[1])
    assert info["id"] == 1 and info["status"] == [] and 7.0 < info["voltage_v"] < 7.8
    item = json.loads(run(sim, capsys, "config", "get", "1", "angle_max", "--json")[1])
    assert item == {"id": 51, "name": "angle_max", "raw": 1350, "value": "135.0 deg"}
    dump = json.loads(run(sim, capsys, "config", "dump", "1", "--json")[1])
    assert dump["items"]["servo_id"] == "1" and len(dump["items"]) == 22 + 12  # the user and drive areas
    assert dump["items"]["angle_max"] == "135.0 deg" and dump["servo"]["serial"] == "0x51a00001"
    raw = json.loads(run(sim, capsys, "config", "dump", "1", "--json", "--raw")[1])
    assert raw["angle_max"] == 1350 and len(raw) == 22 + 12 + 6  # and the RAM items (64-66, 69, 70, 72)


def test_ctrl_c_during_a_wait_releases_nothing(ready):
    proc = servoctl_child("--port", ready.url, "move", "1", "90", "--interval", "3000", "--wait",
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    # Interrupted once it is waiting: the horn is on its way (a loaded PC
    # may take seconds to start Python).
    ready.wait_until(lambda: ready.state(1)["angle"] > 5.0, 60)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in err and "interrupted" in err, err
    ready.wait_until(lambda: ready.state(1)["status"] & 1 == 0, 5)
    assert abs(ready.state(1)["angle"] - 90.0) <= 0.5  # the move went on to its end


def test_a_live_plot_without_a_display_says_so(sim, capsys, monkeypatch):
    """--plot on a machine with no display opened nothing and said nothing."""
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    rc = main(["--port", sim.url, "monitor", "1", "--count", "2", "--plot"], clock=sim.clock_s)
    out, err = capsys.readouterr()
    assert rc == 0 and "warning: --plot: no display" in err and "--plot-file" in err, err
    assert len([line for line in out.splitlines() if line.strip().startswith("1 ")]) == 2, out


def test_a_new_id_already_on_the_bus_is_refused(sim3, capsys):
    """'config set 4 servo_id 2' on a bus with servo 2 made two servos
    answer at 2, silently, exit 0."""
    rc, _, err = run(sim3, capsys, "config", "set", "3", "servo_id", "2")
    assert rc == 2 and "ID 2 already answers on this bus: servo 3 keeps its ID" in err, err
    rc, out, _ = run(sim3, capsys, "scan", "--last", "5")
    assert "3 servo(s) found" in out and "servo 3 at" in out
    assert sim3.state(1)["collisions"] == 0
    rc, out, _ = run(sim3, capsys, "config", "set", "3", "servo_id", "7")
    assert rc == 0 and run(sim3, capsys, "ping", "7")[0] == 0 and run(sim3, capsys, "ping", "3")[0] == 3


def test_id_254_is_a_servo_id(tmp_path, capsys):
    """254 was skipped by scan and backup, refused by sync-move, monitor
    and update (IDs are 0..254)."""
    from servoctl.sim import Simulator

    sim = Simulator(fast=True, ids=[254], tcp=True, state_dir=str(tmp_path / "state"))
    sim.start()
    try:
        rc, out, _ = run(sim, capsys, "scan", "--first", "250")
        assert rc == 0 and "servo 254 at 115200 baud" in out, out
        rc, out, _ = run(sim, capsys, "monitor", "254", "--count", "1", "--json")
        assert rc == 0 and '"id": 254' in out
        rc, out, _ = run(sim, capsys, "backup", str(tmp_path / "b.json"))
        assert rc == 0 and "(254)" in out, out
        assert run(sim, capsys, "config", "set", "254", "soft_start_on", "0")[0] == 0
        assert run(sim, capsys, "sync-move", "254:10", "--interval", "200")[0] == 0
        sim.sleep(0.5)
        assert abs(sim.state(254)["angle"] - 10.0) < 0.5
    finally:
        sim.stop()


def test_a_sync_monitor_keeps_the_answers_after_an_absent_servo(tmp_path, capsys):
    """IDs 1, 3, 5 on the bus: servo 2's turn passes in silence and servo
    3 answers after it. The answers that came while servoctl waited for 2
    were thrown away, so 3 was reported silent."""
    from servoctl import group
    from servoctl.sim import Simulator

    with Simulator(fast=True, ids=[1, 3, 5], state_dir=str(tmp_path / "state")) as sim:
        with sim.bus(timeout=0.2) as bus:
            assert sorted(group.sync_monitor(bus, [1, 2, 3])) == [1, 3]
            assert list(group.sync_monitor(bus, [5, 4, 3, 2, 1])) == [5, 3, 1]
        rc, out, _ = run(sim, capsys, "monitor", "1", "2", "3", "--sync", "--count", "1")
        assert rc == 3 and "  2 silent" in out and "3 silent" not in out, out


def test_what_a_new_user_types_gets_a_line_not_a_traceback(ready, capsys):
    """Tracebacks and units met by trying servoctl as a new user: IDs and
    serials checked after parsing, Unicode digits, --power's unit (a bare
    number meant mW to the tool and W to its user), a speed the motor
    cannot reach."""
    rc, _, err = run(ready, capsys, "id", "assign", "0x51a00003", "255")
    assert rc == 2 and "servo IDs are 0..254, not 255" in err, err
    rc, _, err = run(ready, capsys, "id", "assign", "0x51a00003", "abc")
    assert rc == 2 and "not a servo ID" in err, err
    rc, _, err = run(ready, capsys, "update", "\u00b2", "new.img")
    assert rc == 2 and "Traceback" not in err, err
    with pytest.raises(SystemExit) as e:
        main(["--port", ready.url, "move", "1", "10", "--power", "3"])
    assert e.value.code == 2 and "--power takes a unit: '3' could mean 3mW or 3W" in capsys.readouterr().err
    assert run(ready, capsys, "move", "1", "10", "--power", "3W")[0] == 0
    rc, _, err = run(ready, capsys, "config", "set", "1", "power_limit", "2.5W")
    assert rc == 0, err
    rc, _, err = run(ready, capsys, "move", "1", "0", "--multi-turn", "--velocity", "500")
    assert rc == 0 and "500 deg/s is more than the motor turns unloaded at 7.4 V (about 312 deg/s)" in err


@pytest.mark.parametrize("command", [["scan", "--last", "40"], ["info", "1"], ["config", "dump", "1"],
                                     ["faults", "1"], ["store", "1"]])
def test_a_closed_pipe_ends_every_command_quietly(sim3, command):
    """`servoctl scan | head -1` exited 1 without a word (rich's console
    exits 1 on a closed pipe). A reader that has what it wanted and closes
    the pipe ends every command that prints quietly, exit 0, as Unix tools
    do: here it closes after the first line, and what is printed after it
    meets the closed pipe."""
    proc = subprocess.Popen([sys.executable, "-m", "servoctl.cli", "--port", sim3.url, *command],
                            cwd=TOOLS, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline()
    proc.stdout.close()
    err = proc.stderr.read()
    assert proc.wait(timeout=120) == 0 and err == "", (proc.returncode, err)


def test_a_reader_that_stops_reading_gets_no_traceback(ready):
    """`servoctl monitor 1 | head -1`: the pipe closes under servoctl, which
    goes on writing rows until it meets the closed pipe."""
    reader = subprocess.Popen(["head", "-1"], stdin=subprocess.PIPE, stdout=subprocess.DEVNULL)
    proc = subprocess.Popen([sys.executable, "-m", "servoctl.cli", "--port", ready.url, "monitor", "1",
                             "--every", "0.01", "--count", "100000"],
                            cwd=TOOLS, stdout=reader.stdin, stderr=subprocess.PIPE, text=True)
    reader.stdin.close()
    _, err = proc.communicate(timeout=120)
    reader.wait(timeout=30)
    assert proc.returncode == 0 and "Traceback" not in err and "BrokenPipe" not in err, err
