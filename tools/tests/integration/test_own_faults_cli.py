"""servoctl on the servo's own faults against the simulated servo: safe
mode said by info and faults (item 75: the simulator cannot enter it, so
its reads of item 75 are answered 1 here), reset counts by name, --elf's
errors and another board's ELF (a SIGTERM or SIGHUP to calibrate:
test_calibrate_cut.py)."""
import json
import shutil
import subprocess

import pytest

from servoctl import servo as servo_module
from servoctl.cli import main

SAID = "safe mode: the output is held off after 3 fault resets in a row"


def run(sim, capsys, *args):
    rc = main(["--port", sim.url, *args], clock=sim.clock_s)
    out = capsys.readouterr()
    return rc, out.out, out.err


def _in_safe_mode(monkeypatch):
    real = servo_module.Servo.read

    def read(self, key):
        return 1 if key in ("safe_mode", 75) else real(self, key)
    monkeypatch.setattr(servo_module.Servo, "read", read)


def test_info_and_faults_say_safe_mode(sim, capsys, monkeypatch):
    _in_safe_mode(monkeypatch)
    rc, out, _ = run(sim, capsys, "info", "1")
    assert rc == 0 and "  limiter      safe mode\n" in out and SAID in out, out
    assert "a power cycle or an update ends it" in out
    assert json.loads(run(sim, capsys, "info", "1", "--json")[1])["safe_mode"] is True
    rc, out, _ = run(sim, capsys, "faults", "1")
    assert rc == 0 and SAID in out, out
    assert json.loads(run(sim, capsys, "faults", "1", "--json")[1])["safe_mode"] is True


def test_out_of_safe_mode_info_and_faults_say_nothing_of_it(sim, capsys):
    rc, out, _ = run(sim, capsys, "info", "1")
    assert rc == 0 and "  limiter      none\n" in out and "safe mode" not in out, out
    assert json.loads(run(sim, capsys, "info", "1", "--json")[1])["safe_mode"] is False
    rc, out, _ = run(sim, capsys, "faults", "1")
    assert rc == 0 and "safe mode" not in out, out


def test_reset_counts_by_name(sim, capsys):
    rc, out, _ = run(sim, capsys, "config", "get", "1", "reset_counts")
    assert rc == 0 and out == "reset_counts = 0 firmware faults, 0 watchdog, 0 other, 0 brown-out\n"
    got = json.loads(run(sim, capsys, "config", "get", "1", "reset_counts", "--json")[1])
    assert got["raw"] == 0 and got["counts"] == {"firmware_faults": 0, "watchdog": 0, "other": 0, "brown_out": 0}
    assert run(sim, capsys, "config", "get", "1", "reset_counts", "--raw")[1] == "reset_counts = 0\n"


def test_a_missing_or_non_elf_file_is_a_one_line_usage_error(sim, capsys, tmp_path):
    pytest.importorskip("elftools")
    text = tmp_path / "servo.bin"
    text.write_bytes(b"\x00" * 64)
    for path, said in ((tmp_path / "gone.elf", "No such file or directory"), (text, "not an ELF file")):
        rc, out, err = run(sim, capsys, "faults", "1", "--elf", str(path))
        assert rc == 2 and err.count("\n") == 1 and said in err and "Traceback" not in err, err


def _elf(tmp_path, mark: int):
    """An ELF object with a function and the linker's _board_mark symbol."""
    if shutil.which("cc") is None:
        pytest.skip("no C compiler to make an ELF")
    source = tmp_path / f"mark{mark:x}.s"
    source.write_text(f".globl _board_mark\n.set _board_mark, {mark:#x}\n.text\n.globl f\n.type f, @function\n"
                      "f:\n ret\n.size f, .-f\n")
    out = tmp_path / f"mark{mark:x}.o"
    subprocess.run(["cc", "-c", str(source), "-o", str(out)], check=True)
    return out


def test_an_elf_for_another_board_warns(sim, capsys, tmp_path):
    pytest.importorskip("elftools")
    rc, _, err = run(sim, capsys, "faults", "1", "--elf", str(_elf(tmp_path, 0x53420030)))
    assert rc == 0 and "warning" in err and "is for stm32f030k6 (0x0030), servo 1 is host_sim (0x5100)" in err, err
    rc, _, err = run(sim, capsys, "faults", "1", "--elf", str(_elf(tmp_path, 0x53425100)))
    assert rc == 0 and "warning" not in err, err

