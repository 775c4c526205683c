"""Settings as servoctl shows and takes them: a config dump lists every
item a user can set (the RAM ones, 64-72, marked as lost at power-up) and
loads back; a value the schema names is taken by that name; monitor gives
the limiter alike with --sync and without."""
import json

from servoctl.cli import main
from servoctl import registers


def run(sim, capsys, *args):
    rc = main(["--port", sim.url, *args], clock=sim.clock_s)
    out = capsys.readouterr()
    assert "Traceback" not in out.err
    return rc, out.out, out.err


def test_a_dump_lists_every_settable_item_and_loads_back(sim, capsys, tmp_path):
    assert run(sim, capsys, "config", "set", "1", "watchdog_ms", "500")[0] == 0
    assert run(sim, capsys, "config", "set", "1", "jerk_limit", "5")[0] == 0
    rc, out, _ = run(sim, capsys, "config", "dump", "1")
    assert rc == 0
    settable = [i for i in registers.ITEMS if i.writable and i.public]
    for item in settable:
        assert f" {item.name} " in out, item.name
    for name in ("watchdog_ms", "watchdog_action", "derating", "stream_period_ms", "jerk_limit"):
        line = next(line for line in out.splitlines() if f" {name} " in line)
        assert "RAM: lost at power-up" in line, line
    rc, out, _ = run(sim, capsys, "config", "dump", "1", "--json")
    dump = json.loads(out)
    assert dump["ram_items"]["jerk_limit"] == "5 (deg/s^2)/ms" and dump["ram_items"]["watchdog_ms"] == "500 ms"
    assert "lost at power-up" in dump["ram_items_note"]
    assert {i.name for i in settable} <= set(dump["items"]) | set(dump["ram_items"])
    # The dump loads back: the RAM items set again after a power cycle lost them.
    path = tmp_path / "dump.json"
    path.write_text(out)
    sim.control("powercycle 1")
    sim.sleep(0.5)
    assert run(sim, capsys, "config", "get", "1", "jerk_limit")[1].strip() == "jerk_limit = 0 (deg/s^2)/ms (off)"
    rc, out, err = run(sim, capsys, "config", "load", "1", str(path))
    assert rc == 0 and "in RAM: lost at power-up" in out, (out, err)
    assert run(sim, capsys, "config", "get", "1", "jerk_limit")[1].strip() == "jerk_limit = 5 (deg/s^2)/ms"
    assert json.loads(run(sim, capsys, "config", "dump", "1", "--json")[1]) == dump


def test_a_raw_dump_loads_back(sim, capsys, tmp_path):
    assert run(sim, capsys, "config", "set", "1", "oscillation_ms", "400")[0] == 0
    raw = run(sim, capsys, "config", "dump", "1", "--json", "--raw")[1]
    assert json.loads(raw)["oscillation_ms"] == 400
    path = tmp_path / "raw.json"
    path.write_text(raw)
    assert run(sim, capsys, "config", "set", "1", "oscillation_ms", "300")[0] == 0
    assert run(sim, capsys, "config", "load", "1", str(path), "--raw")[0] == 0
    assert json.loads(run(sim, capsys, "config", "dump", "1", "--json", "--raw")[1]) == json.loads(raw)


def test_the_watchdogs_action_is_taken_by_the_name_info_shows(sim, capsys):
    for name, value in (("hold", 0), ("release", 2), ("damp", 1)):
        rc, out, err = run(sim, capsys, "config", "set", "1", "watchdog_action", name)
        assert rc == 0 and out.strip() == f"watchdog_action = {value} ({name})", (out, err)
        assert run(sim, capsys, "config", "get", "1", "watchdog_action")[1].strip() == out.strip()
    assert run(sim, capsys, "config", "set", "1", "watchdog_ms", "200")[0] == 0
    assert run(sim, capsys, "config", "set", "1", "watchdog_action", "hold")[0] == 0
    rc, out, _ = run(sim, capsys, "info", "1")
    assert "200 ms, then hold" in out, out
    rc, _, err = run(sim, capsys, "config", "set", "1", "watchdog_action", "park")
    assert rc == 2 and "hold, damp, release" in err, err
    assert run(sim, capsys, "config", "set", "1", "derating", "off")[0] == 0
    assert run(sim, capsys, "config", "get", "1", "derating", "--raw")[1].strip() == "derating = 0"


def test_monitor_gives_the_limiter_alike_with_sync_and_without(sim, capsys):
    plain = [json.loads(line) for line in
             run(sim, capsys, "monitor", "1", "--json", "--count", "2", "--every", "0.02")[1].splitlines()]
    synced = [json.loads(line) for line in
              run(sim, capsys, "monitor", "1", "--sync", "--json", "--count", "2", "--every", "0.02")[1].splitlines()]
    assert [r["limiter"] for r in plain] == [r["limiter"] for r in synced] == ["none", "none"]


def test_a_backup_carries_the_ram_items_and_restores_them(sim, capsys, tmp_path):
    assert run(sim, capsys, "config", "set", "1", "watchdog_action", "release")[0] == 0
    backup = tmp_path / "bus.json"
    assert run(sim, capsys, "backup", str(backup), "--ids", "1")[0] == 0
    assert json.loads(backup.read_text())["servos"][0]["ram_items"]["watchdog_action"] == "2"
    sim.control("powercycle 1")
    sim.sleep(0.5)
    assert run(sim, capsys, "restore", str(backup))[0] == 0
    assert run(sim, capsys, "config", "get", "1", "watchdog_action")[1].strip() == "watchdog_action = 2 (release)"
