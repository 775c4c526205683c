"""A board's facts have one reader (servo_image.board_facts) that every tool
uses, a board's CPU comes from the chip family its board.cmake names, and
the part it names holds its flash map and RAM to the part's own facts."""
import shutil
import subprocess
import sys
from pathlib import Path

from servo_image import board_facts
from servoctl import image as img
from vboard import board as vb


def test_every_tool_reads_the_same_board_facts():
    for name in ("stm32f103", "stm32f030k6", "qemu_stm32vl", "host_sim"):
        facts = board_facts.defines(name)
        assert facts["BOARD_ID"] == img.boards()[name].id
        assert vb.board_h(name) == facts


def test_the_cpu_is_the_family_s():
    assert {n: b.cpu for n, b in img.boards().items()} == {
        "host_sim": "", "qemu_stm32vl": "cortex-m3", "stm32f030k6": "cortex-m0",
        "stm32f103": "cortex-m3", "stm32g031k8": "cortex-m0plus"}


def test_a_family_is_declared_once(tmp_path):
    """A board.cmake names its family; one that sets its CPU itself wins."""
    (tmp_path / "board.cmake").write_text(
        "include(${PROJECT_SOURCE_DIR}/cmake/family-stm32f0.cmake)\n")
    assert board_facts.cpu(tmp_path) == "cortex-m0"
    (tmp_path / "board.cmake").write_text(
        "include(${PROJECT_SOURCE_DIR}/cmake/family-stm32f0.cmake)\nset(SERVO_BOARD_CPU cortex-m4)\n")
    assert board_facts.cpu(tmp_path) == "cortex-m4"


def test_a_board_h_s_includes_are_followed():
    """The reference servo's front end is declared once
    (boards/common/reference_servo.h) and read for every board that includes
    it; host_sim's own ID overrides the reference board's it includes."""
    for name in ("stm32f103", "stm32f030k6", "qemu_stm32vl", "host_sim"):
        facts = board_facts.defines(name)
        assert facts["BOARD_SUPPLY_UV_PER_COUNT"] == 8862, name
        assert facts["BOARD_MOTOR_MOHM"] == 2741, name
    assert board_facts.defines("host_sim")["BOARD_ID"] == 0x5100


def test_every_shipped_board_fits_its_part():
    for name in ("stm32f103", "stm32f030k6", "qemu_stm32vl", "host_sim"):
        assert board_facts.check(name) == [], name
    assert board_facts.part_name("stm32f030k6") == "stm32f030k6"
    assert board_facts.parts()["stm32f030k6"]["ram_size"] == 4096


def _board_like(tmp_path, name, header_edits=(), part=None):
    """A copy of a shipped board's folder with board.h's lines edited (old,
    new) and, given one, another part named in board.cmake."""
    folder = tmp_path / name
    folder.mkdir(parents=True)
    source = board_facts.boards_dir() / name
    header = (source / "board.h").read_text()
    for old, new in header_edits:
        assert old in header, old
        header = header.replace(old, new)
    (folder / "board.h").write_text(header)
    cmake = (source / "board.cmake").read_text()
    if part is not None:
        cmake = cmake.replace(f"set(SERVO_BOARD_PART {board_facts.part_name(name)})",
                              f"set(SERVO_BOARD_PART {part})" if part else "")
    (folder / "board.cmake").write_text(cmake)
    return folder


def test_a_board_its_part_contradicts_is_named_fact_by_fact(tmp_path):
    """The review's boards: 64 KB of RAM declared on a 4 KB part, a slot
    past the flash's end, a config page off its erase unit, 1 KB pages
    declared on a 2 KB-page part (an erase of the spare page would wipe the
    newest record), and another CPU."""
    cases = [
        ("stm32f030k6", [("#define BOARD_RAM_SIZE 4096", "#define BOARD_RAM_SIZE 65536")], None,
         "BOARD_RAM_SIZE 65536 are not within the part's 4096 B of RAM"),
        ("stm32f030k6", [("#define BOARD_SLOT_PAGES 24", "#define BOARD_SLOT_PAGES 56")], None,
         "ends past the part's 32 KB of flash"),
        ("stm32f103", [("#define BOARD_CONFIG_PAGE1 0x0800FC00", "#define BOARD_CONFIG_PAGE1 0x0800FA00")], None,
         "BOARD_CONFIG_PAGE1 at 0x0800FA00, 1024 B, is not on the part's 1024-byte erase unit"),
        ("stm32f103", [("#define BOARD_FAULT_PAGE1 0x0800F400", "#define BOARD_FAULT_PAGE1 0x0800F800")], None,
         "BOARD_FAULT_PAGE1 and BOARD_CONFIG_PAGE0 overlap"),
        ("stm32f030k6", [], "stm32g031k8", "BOARD_FLASH_PAGE 1024 is not the part's erase unit, 2048 B"),
        ("stm32f030k6", [], "stm32f103c8", "its family's CPU cortex-m0 is not the part's cortex-m3"),
        ("stm32f030k6", [], "", "board.cmake names no part"),
        ("stm32f030k6", [], "stm32f999", "names the part 'stm32f999', which hal/ports/parts.toml does not have"),
        # An STM32F1 board's pins and instances, against its part's package.
        ("stm32f103", [("#define BOARD_BUS_TX_PIN 0x09", "#define BOARD_BUS_TX_PIN 0x38")], None,
         "BOARD_BUS_TX_PIN 0x38 (PD8) is not a pin of the part's package (PA0-PA15, PB0-PB15, PC13-PC15, "
         "PD0-PD1)"),
        ("stm32f103", [("#define BOARD_BRIDGE_TIMER 3", "#define BOARD_BRIDGE_TIMER 5")], None,
         "BOARD_BRIDGE_TIMER 5: the part has no TIM5 (its timers: 2, 3, 4)"),
        ("stm32f103", [("#define BOARD_BUS_USART 1", "#define BOARD_BUS_USART 4")], None,
         "BOARD_BUS_USART 4: the part has no USART4"),
        ("stm32f103", [("#define BOARD_ADC_NTC 2", "#define BOARD_ADC_NTC 12")], None,
         "BOARD_ADC_NTC 12: the part's ADC has inputs 0-9 on its pins"),
        # A fact as anything but a plain number is refused, not skipped (a
        # config page past the flash in parentheses went unchecked).
        ("stm32g031k8", [("#define BOARD_CONFIG_PAGE0 0x0800F000", "#define BOARD_CONFIG_PAGE0 (0x08010000)")],
         None, "BOARD_CONFIG_PAGE0 is '(0x08010000)': a board fact is a plain number"),
        ("stm32g031k8", [("#define BOARD_CONFIG_PAGE0 0x0800F000", "#define  BOARD_CONFIG_PAGE0  0x08010000u")],
         None, "BOARD_CONFIG_PAGE0 is '0x08010000u': a board fact is a plain number"),
        ("stm32g031k8", [("#define BOARD_CONFIG_PAGE0 0x0800F000", "#define BOARD_CONFIG_PAGE0  0x08010000 /* x */")],
         None, "BOARD_CONFIG_PAGE0 at 0x08010000, 2048 B, ends past the part's 64 KB"),
    ]
    for i, (name, edits, part, said) in enumerate(cases):
        problems = board_facts.check(_board_like(tmp_path / str(i), name, edits, part))
        assert any(said in line for line in problems), (said, problems)


def test_the_build_s_check_exits_with_a_line_a_problem(tmp_path):
    """What cmake/arm-image.cmake runs at configure time (servo_board_facts)."""
    script = Path(board_facts.__file__)
    good = subprocess.run([sys.executable, script, "--check", board_facts.boards_dir() / "stm32f030k6"],
                          capture_output=True, text=True)
    assert good.returncode == 0 and good.stderr == "" and good.stdout == ""
    # With --facts, the numbers the build's limits come from, in decimal
    # whichever way board.h writes them (a slot of 0x18 pages).
    hex_pages = _board_like(tmp_path / "hex", "stm32f030k6",
                            [("#define BOARD_SLOT_PAGES 24", "#define BOARD_SLOT_PAGES 0x18")])
    facts = subprocess.run([sys.executable, script, "--check", "--facts", hex_pages],
                           capture_output=True, text=True)
    assert facts.returncode == 0
    lines = facts.stdout.splitlines()
    assert "BOARD_SLOT_PAGES=24" in lines and "BOARD_FLASH_BASE=134217728" in lines
    bad = _board_like(tmp_path, "stm32f030k6", [("#define BOARD_RAM_SIZE 4096", "#define BOARD_RAM_SIZE 8192")])
    run = subprocess.run([sys.executable, script, "--check", bad], capture_output=True, text=True)
    assert run.returncode == 1
    assert run.stderr.splitlines() == [
        "board check: stm32f030k6: BOARD_RAM_BASE 0x20000000 and BOARD_RAM_SIZE 8192 are not within "
        "the part's 4096 B of RAM at 0x20000000 (stm32f030k6)"]


def test_an_installed_copy_reads_the_tree_it_is_given_or_runs_in(tmp_path):
    """pip install ./tools (not -e) leaves servo_image without the firmware
    tree beside it: the boards are read from $SERVO_FIRMWARE_ROOT or the
    clone the command runs in (a folder of it too), and without either
    the image is refused saying how to give one, not with an empty list."""
    site = tmp_path / "site"
    shutil.copytree(Path(board_facts.__file__).parent, site / "servo_image",
                    ignore=shutil.ignore_patterns("__pycache__"))
    script = """
import servo_image
print(sorted(servo_image.boards()))
print(servo_image.board_named(servo_image.boards().get("stm32f030k6", servo_image.Board("", 0x30)).id))
try:
    servo_image.make("absent.bin", "1", "stm32f030k6", "out.img")
except servo_image.ImageError as e:
    print(e)
"""
    repo = Path(board_facts.__file__).resolve().parents[2]

    def run(cwd, **env):
        done = subprocess.run([sys.executable, "-S", "-c", script], capture_output=True, text=True, cwd=cwd,
                              env={"PYTHONPATH": str(site), **env}, timeout=60)
        assert done.returncode == 0, done.stderr
        return done.stdout.splitlines()

    assert run(tmp_path) == ["[]", "board 0x0030 (unnamed: no firmware tree found; set SERVO_FIRMWARE_ROOT)",
                             "no firmware tree found: run from a clone of the firmware or set SERVO_FIRMWARE_ROOT"]
    elsewhere = run(tmp_path, SERVO_FIRMWARE_ROOT=str(tmp_path))
    assert elsewhere[2] == (f"no firmware tree found: run from a clone of the firmware or set SERVO_FIRMWARE_ROOT "
                            f"(SERVO_FIRMWARE_ROOT={tmp_path} has no firmware/boards and hal/ports/parts.toml)")
    for found in (run(tmp_path, SERVO_FIRMWARE_ROOT=str(repo)), run(repo / "tools")):
        assert "'stm32f030k6'" in found[0] and found[1].startswith("stm32f030k6 (0x"), found
        assert found[2].startswith("cannot read absent.bin"), found
