"""Config and backup files say what they mean: units on every
value, the servo they came from; raw files load only when marked as raw;
config diff compares servos, files and factory values, by serial number
where known."""
import json

import pytest

from servoctl import registers
from servoctl.cli import main
from servoctl.sim import Simulator


def run(sim, capsys, *args):
    rc = main(["--port", sim.url, *args], clock=sim.clock_s)
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_a_hand_written_file_means_what_it_says(sim, capsys, tmp_path):
    """{"angle_max": 45} loaded as 4.5 deg. A plain number now needs --raw
    (the old files' protocol units); written with a unit it is taken."""
    f = tmp_path / "hand.json"
    f.write_text(json.dumps({"angle_max": 45}))
    rc, _, err = run(sim, capsys, "config", "load", "1", str(f))
    assert rc == 2 and "plain numbers: a raw file in protocol units" in err and "--raw" in err, err
    assert run(sim, capsys, "config", "get", "1", "angle_max")[1] == "angle_max = 135.0 deg\n"
    f.write_text(json.dumps({"angle_max": "45 deg", "power_limit": "2.5W"}))
    rc, out, _ = run(sim, capsys, "config", "load", "1", str(f))
    assert rc == 0 and "loaded 2 item(s)" in out
    assert run(sim, capsys, "config", "get", "1", "angle_max")[1] == "angle_max = 45.0 deg\n"
    assert run(sim, capsys, "config", "get", "1", "power_limit")[1] == "power_limit = 2500 mW\n"
    f.write_text(json.dumps({"servoctl_config": 2, "items": {"power_limit": 2.5}}))
    rc, _, err = run(sim, capsys, "config", "load", "1", str(f))
    assert rc == 2 and "could mean 2.5mW or 2.5W" in err, err


def test_an_old_raw_file_loads_when_marked_raw(sim, capsys, tmp_path):
    f = tmp_path / "old.json"
    f.write_text(json.dumps({"angle_max": 450, "stall_power": 1234}))
    rc, out, _ = run(sim, capsys, "config", "load", "1", str(f), "--raw")
    assert rc == 0 and "a raw file: protocol units" in out, out
    assert run(sim, capsys, "config", "get", "1", "angle_max")[1] == "angle_max = 45.0 deg\n"


def test_every_value_survives_the_file_exactly(sim, capsys, tmp_path):
    """A file written by save reads back as the same protocol values, the
    temperature's NTC value included (written in degC to enough places)."""
    for name, text in (("temperature_limit", "652ADC"), ("angle_min", "-90.5"), ("baud", "115200"),
                       ("soft_start_time", "1234ms"), ("low_voltage", "5.1V")):
        assert run(sim, capsys, "config", "set", "1", name, text)[0] == 0
    before = json.loads(run(sim, capsys, "config", "dump", "1", "--json", "--raw")[1])
    f = tmp_path / "cfg.json"
    assert run(sim, capsys, "config", "save", "1", str(f))[0] == 0
    assert run(sim, capsys, "config", "reset", "1")[0] == 0
    assert run(sim, capsys, "config", "load", "1", str(f))[0] == 0
    assert json.loads(run(sim, capsys, "config", "dump", "1", "--json", "--raw")[1]) == before
    assert json.loads(f.read_text())["items"]["baud"] == "115200 baud"


def test_config_diff(tmp_path, capsys):
    with Simulator(fast=True, ids=[1, 2], state_dir=str(tmp_path / "state")) as sim:
        assert run(sim, capsys, "config", "set", "2", "stall_power", "2.5W")[0] == 0
        rc, out, _ = run(sim, capsys, "config", "diff", "1", "2")
        assert rc == 1, out
        assert "servo 1 (serial 0x51a00001) | servo 2 (serial 0x51a00002)" in out
        assert "stall_power" in out and "10000 mW" in out and "2500 mW" in out
        assert "servo_id" in out  # 1 and 2
        rc, out, _ = run(sim, capsys, "config", "diff", "1", "factory")
        assert rc == 1 and "servo_id" in out and "stall_power" not in out, out
        # A backup is matched by serial: servo 2's entry, although the file
        # lists it under another ID.
        backup = tmp_path / "bus.json"
        assert run(sim, capsys, "backup", str(backup))[0] == 0
        data = json.loads(backup.read_text())
        data["servos"][1]["servo"]["id"] = 7
        backup.write_text(json.dumps(data))
        rc, out, _ = run(sim, capsys, "config", "diff", "2", str(backup))
        assert rc == 0 and "the same" in out and "serial 0x51a00002" in out, out
        rc, out, _ = run(sim, capsys, "config", "diff", "2", str(backup), "--json")
        assert rc == 0 and json.loads(out)["differ"] == {}
        rc, out, _ = run(sim, capsys, "config", "diff", str(backup), "factory")
        assert rc == 1 and "stall_power" in out
        rc, _, err = run(sim, capsys, "config", "diff", "1", "nonsense")
        assert rc == 2 and "an ID, a config or backup file, or 'factory'" in err


def test_a_tuned_servos_drive_area_goes_with_its_file(sim, capsys, tmp_path):
    """The drive area (items 80-91: calibrate's and tune's) is in config
    files and backups, and in config diff: a tuned servo's file brings its
    tuning back, as a backup does."""
    tuned = {"gain_kp": "700", "gain_kd": "12000", "gear_ratio": "-387", "encoder_zero": "1234"}
    for name, text in tuned.items():
        assert run(sim, capsys, "config", "set", "1", name, text)[0] == 0
    f, b = tmp_path / "tuned.json", tmp_path / "all.json"
    assert run(sim, capsys, "config", "save", "1", str(f))[0] == 0
    assert run(sim, capsys, "backup", str(b), "--ids", "1")[0] == 0
    items = json.loads(f.read_text())["items"]
    assert items["gain_kd"] == "12000 Q15 duty/(0.1deg/tick)" and items["gear_ratio"] == "-387", items
    # Other values (a 1 in each would make the loop unstable: refused, docs/safety.md)
    for name, text in {"gain_kp": "546", "gain_kd": "3000", "gear_ratio": "345", "encoder_zero": "1"}.items():
        assert run(sim, capsys, "config", "set", "1", name, text)[0] == 0
    rc, out, _ = run(sim, capsys, "config", "diff", "1", str(f))
    assert rc == 1 and "gain_kd" in out and "encoder_zero" in out, out
    assert run(sim, capsys, "config", "load", "1", str(f))[0] == 0
    assert run(sim, capsys, "config", "get", "1", "gain_kd")[1].startswith("gain_kd = 12000")
    assert run(sim, capsys, "config", "set", "1", "gain_kp", "600")[0] == 0
    assert run(sim, capsys, "restore", str(b))[0] == 0
    assert run(sim, capsys, "config", "get", "1", "gain_kp")[1].startswith("gain_kp = 700 ")
    rc, out, _ = run(sim, capsys, "config", "diff", "1", "factory")
    assert rc == 1 and "gear_ratio" in out and "gain_kp" in out, out


def test_with_link_writes_everything_then_moves_the_servo(sim, capsys, tmp_path):
    """--with-link: a file with another ID and rate loads whole (RAM and
    drive items too), the ID and rate written last, the host following."""
    f = tmp_path / "c.json"
    assert run(sim, capsys, "config", "save", "1", str(f))[0] == 0
    doc = json.loads(f.read_text())
    doc["items"].update(servo_id="5", baud="1000000 baud", gain_kp="500", power_limit="9000 mW")
    doc["ram_items"]["oscillation_ms"] = "250"
    f.write_text(json.dumps(doc))
    control = str(sim.control_port)
    rc, out, err = run(sim, capsys, "--sim-control", control, "config", "load", "1", str(f), "--with-link")
    assert rc == 0 and "(now ID 5;" in out and "host rate is set to 1000000 too" in out, out + err
    for name, shown in (("gain_kp", "500"), ("power_limit", "9000 mW"), ("oscillation_ms", "250")):
        rc, out, err = run(sim, capsys, "--baud", "1000000", "--sim-control", control, "config", "get", "5", name)
        assert rc == 0 and out.startswith(f"{name} = {shown}"), out + err
    doc["items"].update(servo_id="1", baud="115200 baud")  # back as it was, the same way
    f.write_text(json.dumps(doc))
    rc, out, err = run(sim, capsys, "--baud", "1000000", "--sim-control", control, "config", "load", "5", str(f),
                       "--with-link")
    assert rc == 0 and "(now ID 1;" in out and sim.state(1)["host_baud"] == 115200, out + err


def test_ram_items_carry_their_units_in_files(sim, capsys, tmp_path):
    """RAM items were written as bare numbers ("watchdog_ms": "0") and
    "500 ms" was refused: they carry and take units as the user area's do;
    a bare number (a file written before) is still ms."""
    f = tmp_path / "ram.json"
    assert run(sim, capsys, "config", "save", "1", str(f))[0] == 0
    doc = json.loads(f.read_text())
    assert doc["ram_items"]["oscillation_ms"] == "300 ms" and doc["ram_items"]["watchdog_action"] == "1"
    doc["ram_items"].update(watchdog_ms="0.5 s", oscillation_ms="250 ms")
    f.write_text(json.dumps(doc))
    rc, out, err = run(sim, capsys, "config", "load", "1", str(f))
    assert rc == 0, out + err
    assert run(sim, capsys, "config", "get", "1", "watchdog_ms")[1].startswith("watchdog_ms = 500")
    doc["ram_items"].update(watchdog_ms="0", oscillation_ms="300")
    f.write_text(json.dumps(doc))
    assert run(sim, capsys, "config", "load", "1", str(f))[0] == 0
    assert run(sim, capsys, "config", "get", "1", "oscillation_ms")[1].startswith("oscillation_ms = 300")


def test_restore_with_link_follows_the_servos_rates(sim3, capsys, tmp_path):
    """A backup of three servos at 1 Mbaud restored with --with-link on a
    bus at 115 200 where servo 2 already speaks 1 Mbaud: the host follows,
    reaching each servo at its rate, and speaks the servos' new rate after
    (before: servo 2 was not reached, and nothing followed the change)."""
    b = tmp_path / "b.json"
    assert run(sim3, capsys, "backup", str(b), "--ids", "1", "2", "3")[0] == 0
    doc = json.loads(b.read_text())
    for entry in doc["servos"]:
        entry["items"]["baud"] = "1000000 baud"
    b.write_text(json.dumps(doc))
    assert run(sim3, capsys, "config", "set", "2", "baud", "1000000")[0] == 0  # the host's stays
    control = str(sim3.control_port)
    rc, out, err = run(sim3, capsys, "--sim-control", control, "restore", str(b), "--with-link")
    assert rc == 0 and "servos 1, 3 now speak 1000000 baud" in out, out + err
    assert sim3.state(1)["host_baud"] == 1000000
    rc, out, err = run(sim3, capsys, "--baud", "1000000", "--sim-control", control, "scan", "--last", "4")
    assert rc == 0 and "3 servo(s) found" in out, out + err


def test_a_socket_link_takes_the_simulators_host_rate(sim, capsys):
    """After `config set 1 baud 1000000` with --sim-control (hostbaud set),
    later commands given --sim-control but no --baud take the simulator's
    host rate: before, bench and stream judged a 1 Mbaud wire at 115200."""
    control = str(sim.control_port)
    assert run(sim, capsys, "--sim-control", control, "config", "set", "1", "baud", "1000000")[0] == 0
    rc, out, err = run(sim, capsys, "--sim-control", control, "bench", "--ids", "1", "--seconds", "0.2")
    assert rc == 0 and "at 1000000 baud" in out, out + err


def test_another_servos_calibration_is_not_loaded_unless_asked(tmp_path, capsys):
    """Servo 2's file into servo 1 carried servo 2's zero, amplifier offset
    and direction: servo 1 then read 8 deg off (its limits moved with it),
    and a negated gear ratio from leads swapped on servo 2 would run servo
    1's loop the wrong way round; and servo 2's joint range (narrowed
    limits, in servo 2's zero). They stay servo 1's unless asked."""
    with Simulator(fast=True, ids=[1, 2], state_dir=str(tmp_path / "state")) as sim:
        for name, text in {"encoder_zero": "91", "gear_ratio": "-345", "stall_power": "2.5W",
                           "angle_max": "20", "angle_min": "-20"}.items():
            assert run(sim, capsys, "config", "set", "2", name, text)[0] == 0
        f = tmp_path / "two.json"
        assert run(sim, capsys, "config", "save", "2", str(f))[0] == 0
        rc, out, _ = run(sim, capsys, "config", "load", "1", str(f))
        assert rc == 0 and "its calibration, drive train and joint range not loaded" in out and "encoder_zero" in out, out
        assert run(sim, capsys, "config", "get", "1", "encoder_zero")[1].startswith("encoder_zero = 0 ")
        assert run(sim, capsys, "config", "get", "1", "gear_ratio")[1] == "gear_ratio = 345\n"
        assert run(sim, capsys, "config", "get", "1", "stall_power")[1].startswith("stall_power = 2500")
        # servo 2's joint range, in servo 2's zero, is not servo 1's either
        assert "angle_max" in out and run(sim, capsys, "config", "get", "1", "angle_max")[1] == "angle_max = 135.0 deg\n"
        # And servo 1's own joint range is not replaced by a file's factory limits (or limits off).
        assert run(sim, capsys, "config", "set", "1", "angle_max", "30")[0] == 0
        assert run(sim, capsys, "config", "set", "2", "angle_max", "135")[0] == 0
        assert run(sim, capsys, "config", "set", "2", "angle_min", "-135")[0] == 0
        factory = tmp_path / "factory.json"
        assert run(sim, capsys, "config", "save", "2", str(factory))[0] == 0
        assert run(sim, capsys, "config", "load", "1", str(factory))[0] == 0
        assert run(sim, capsys, "config", "get", "1", "angle_max")[1] == "angle_max = 30.0 deg\n"
        rc, out, _ = run(sim, capsys, "config", "load", "1", str(f), "--with-calibration")
        assert rc == 0 and "not loaded" not in out, out
        assert run(sim, capsys, "config", "get", "1", "gear_ratio")[1] == "gear_ratio = -345\n"


def test_a_file_of_no_serial_brings_no_calibration_nor_changes_a_joints_range(tmp_path, capsys):
    """A raw dump (no serial) of servo 1 into servo 2, a joint: it reversed
    servo 2's direction, moved its zero and put its limits back to +-135.
    A file not known to be this servo's brings none of that; a hand-written
    file still sets the limits of a servo that is no joint. And config
    reset says the joint's range it takes away."""
    with Simulator(fast=True, ids=[1, 2], state_dir=str(tmp_path / "state")) as sim:
        for name, text in {"encoder_zero": "500", "gear_ratio": "-345"}.items():
            assert run(sim, capsys, "config", "set", "1", name, text)[0] == 0
        for name, text in {"angle_min": "-60", "angle_max": "60"}.items():
            assert run(sim, capsys, "config", "set", "2", name, text)[0] == 0
        rc, out, _ = run(sim, capsys, "config", "dump", "1", "--json", "--raw")
        raw = tmp_path / "raw1.json"
        raw.write_text(out)
        rc, out, _ = run(sim, capsys, "config", "load", "2", str(raw), "--raw")
        assert rc == 0 and "a file of no serial" in out, out
        assert run(sim, capsys, "config", "get", "2", "gear_ratio")[1] == "gear_ratio = 345\n"
        assert run(sim, capsys, "config", "get", "2", "angle_max")[1] == "angle_max = 60.0 deg\n"
        rc, out, _ = run(sim, capsys, "config", "reset", "2")
        assert rc == 0 and "-60.0..60.0 deg (a joint's range), are the factory's +-135 deg again" in out, out
