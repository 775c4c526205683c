"""Figures and commands in the docs against what produces them, so they
cannot drift: docs/footprint.md against the linker maps and images of the
build (scripts/footprint.sh's own reading) and its stack table against the
ELFs and cmake/stack-report.py, the README's robot loop against
docs/streaming.md's table (scripts/stream_bench.sh), each board's
BOARD_TICK_AND_PASS_US against docs/benchmark.md's table (which the test
command checks against the target benchmark: run_target_bench.py --doc),
every `servoctl config set` in the docs against servoctl's own parser, the
Python servoctl needs against tools/pyproject.toml, building.md's list of
docs against docs/. Reads files and runs the build's own readers: it costs
the suite a few seconds."""
import math
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from servoctl import registers, units

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
F103 = ROOT / "build/arm/firmware/boards/stm32f103"
F030 = ROOT / "build/arm-m0/firmware/boards/stm32f030k6"
G031 = ROOT / "build/arm-g0/firmware/boards/stm32g031k8"
CLOCK_MHZ = {"stm32f103": 72, "stm32f030k6": 48, "stm32g031k8": 64}  # run_target_bench.py's CLOCK_MHZ, by board


def number(text: str) -> int:
    """A figure as the docs write it: '25 028 B', '**24 248 B**'."""
    return int(re.sub(r"[^0-9]", "", text))


def table(text: str, header: str) -> list:
    """The rows (lists of cells) of the Markdown table whose header line
    starts with header."""
    rows, inside = [], False
    for line in text.splitlines():
        if line.startswith(header):
            inside = True
            continue
        if inside and not line.startswith("|"):
            break
        if inside and not line.startswith("|---"):
            rows.append([c.strip() for c in line.strip("|").split("|")])
    assert rows, f"no table with the header {header!r}"
    return rows


def table_rows(text: str, header: str) -> dict:
    """{first cell: the other cells} of that table."""
    return {cells[0]: cells[1:] for cells in table(text, header)}


def footprint_modules(map_path: Path) -> dict:
    out = subprocess.run([sys.executable, str(ROOT / "cmake/footprint.py"), str(map_path)],
                         capture_output=True, text=True, check=True).stdout
    return {name: int(cells[0].strip("*")) for name, cells in table_rows(out, "| module |").items()}


def image_flash(elf: Path) -> int:
    line = subprocess.run(["sh", str(ROOT / "cmake/check-image.sh"), str(elf)],
                          capture_output=True, text=True).stdout
    return int(re.search(r"flash (\d+) B", line).group(1))


needs_arm = pytest.mark.skipif(not all((d / f"servo_{d.name}.map").exists() for d in (F103, F030, G031)),
                               reason="no ARM build (cmake --build --preset arm, arm-m0, arm-g0)")


@needs_arm
def test_footprint_md_is_what_the_build_links():
    doc = (DOCS / "footprint.md").read_text()
    built = [footprint_modules(d / f"servo_{d.name}.map") for d in (F103, F030, G031)]
    modules = table_rows(doc, "| module |")
    wrong = [f"{name}: {cells[:3]} in the doc, {[b.get(name, 0) for b in built]} built"
             for name, cells in modules.items()
             if [number(c) for c in cells[:3]] != [b.get(name, 0) for b in built]]
    missing = sorted(set().union(*built) - set(modules))
    assert not wrong and not missing, f"docs/footprint.md (bash scripts/footprint.sh): {wrong} {missing}"
    images = table_rows(doc, "| image |")
    for row, elf in (("reference board, STM32F103 (Cortex-M3)", F103 / "servo_stm32f103.elf"),
                     ("Cortex-M0 board, STM32F030K6 (`arm-m0`)", F030 / "servo_stm32f030k6.elf"),
                     ("Cortex-M0+ board, STM32G031K8 (`arm-g0`)", G031 / "servo_stm32g031k8.elf"),
                     ("bootloader, STM32F103", F103 / "servo_stm32f103_boot.elf"),
                     ("bootloader, STM32F030K6", F030 / "servo_stm32f030k6_boot.elf"),
                     ("bootloader, STM32G031K8", G031 / "servo_stm32g031k8_boot.elf")):
        assert number(images[row][0]) == image_flash(elf), f"docs/footprint.md: {row}"


@needs_arm
def test_footprint_mds_stack_table_has_every_board_and_the_builds_figures():
    """The stack table's boards and its reserved and static columns (the
    ELF's and stack-report.py's, which do not move); the deepest measured
    moves a little from run to run (the doc says why), under the static."""
    from vboard import stack_depth
    rows = table_rows((DOCS / "footprint.md").read_text(), "| board | stack reserved |")
    assert list(rows) == list(stack_depth.BOARDS), "docs/footprint.md: rerun python -m vboard.stack_depth --markdown"
    for board, (reserved, static, deepest) in rows.items():
        worst, _ = stack_depth.static_worst(board)
        assert (number(static), number(reserved)) == (worst, stack_depth.reserved_bytes(board)), board
        assert 0 < number(deepest) < worst, board


def test_the_readme_gives_the_robot_loop_of_streaming_md():
    ratios = [float(x) for cells in table((DOCS / "streaming.md").read_text(), "| servos |")
              for x in re.findall(r"[0-9]\.[0-9]+", cells[4])]
    readme = (ROOT / "README.md").read_text()
    said = re.search(r"a robot loop at ([0-9.]+)–([0-9.]+) of the wire", readme)
    assert said and (float(said.group(1)), float(said.group(2))) == (min(ratios), max(ratios)), \
        (said and said.group(0), min(ratios), max(ratios))


@pytest.mark.parametrize("board, column", [("stm32f103", 1), ("stm32f030k6", 3), ("stm32g031k8", 5)])
def test_each_boards_tick_and_pass_is_the_benchmarks(board, column):
    """BOARD_TICK_AND_PASS_US: the longest control tick and a main-loop
    pass (servo_tick_worst + idle_poll) at the board's clock, rounded up."""
    rows = table_rows((DOCS / "benchmark.md").read_text(), "| figure | M3 instr |")
    cycles = sum(number(rows[key][column].split("(")[0]) for key in ("servo_tick_worst", "idle_poll"))
    header = (ROOT / "firmware/boards" / board / "board.h").read_text()
    given = int(re.search(r"#define BOARD_TICK_AND_PASS_US (\d+)", header).group(1))
    assert given == math.ceil(cycles / CLOCK_MHZ[board]), (board, given, cycles / CLOCK_MHZ[board])


def test_every_config_set_in_the_docs_is_taken():
    """What a reader copies from the docs, servoctl takes (units.to_raw,
    as `servoctl config set` parses it); docs/bring-up.md's high_voltage
    12600 was refused: it needs a unit."""
    seen = 0
    for path in [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]:
        text = re.sub(r"\s+", " ", path.read_text())
        for m in re.finditer(r"servoctl (?:--[a-z-]+ \S+ )*config set (\d+|ID|N) ([a-z_0-9]+) ([^\s`']+)", text):
            if m.group(3).startswith(("-", "<", "N")):
                continue
            seen += 1
            try:
                units.to_raw(registers.find(m.group(2)), m.group(3))
            except Exception as e:  # noqa: BLE001 - the message names the doc
                pytest.fail(f"{path.name}: `{m.group(0)}` is refused: {e}")
    assert seen >= 5


def test_pyproject_asks_the_python_servoctl_needs():
    needs = (3, 11) if any("import tomllib" in p.read_text() for p in (ROOT / "tools/servoctl").glob("*.py")) else (3, 9)
    project = tomllib.loads((ROOT / "tools/pyproject.toml").read_text())["project"]
    floor = tuple(int(x) for x in re.match(r">=\s*(\d+)\.(\d+)", project["requires-python"]).groups())
    assert floor >= needs, project["requires-python"]


def test_building_md_lists_every_doc():
    listed = set(re.findall(r"`([a-z-]+\.md)`", (DOCS / "building.md").read_text()))
    missing = sorted(p.name for p in DOCS.glob("*.md") if p.name not in listed)
    assert not missing, f"docs/building.md's list of docs leaves out {missing}"


def test_no_test_names_an_issue_number():
    """A test says what it checks: an issue's number goes stale."""
    found = [f"{p.relative_to(ROOT)}:{n}" for base in ("tools/tests", "tests/unit", "tests/fuzz", "tests/bench")
             for p in sorted((ROOT / base).rglob("*")) if p.suffix in (".py", ".c", ".h", ".sh")
             for n, line in enumerate(p.read_text(errors="replace").splitlines(), 1)
             if re.search(r"\bissues? \d+", line, re.IGNORECASE)]
    assert not found, found


def test_the_readme_and_the_demo_start_a_servo_as_it_comes():
    """The README says a new servo is at the schema's factory ID and rate;
    the demo starts its simulated servo there and drives that ID (it
    started ID 1 while the README said 0)."""
    servo_id, baud = registers.find("servo_id").default, registers.BAUD_RATES[registers.find("baud").default]
    readme = (ROOT / "README.md").read_text()
    assert f"a new servo is at ID {servo_id}, {baud} baud" in readme
    demo = (ROOT / "scripts/demo.sh").read_text()
    assert re.findall(r"servo_sim --id (\d+)", demo) == [str(servo_id)]
    driven = re.findall(r"^step (?:info|config set|move|record) (\d+)", demo, re.M)
    assert driven and set(driven) == {str(servo_id)}, driven
