"""servobus's structs are sized by SB_MAX_SERVOS: a program built with
another value than the library's does not link (it wrote past its own
smaller sb_bus in sb_bus_init, found by ASan). The functions that set the
structs up carry the number in their link names."""
import shutil
import subprocess

import pytest

from .launchers import REPO

SERVOBUS = REPO / "tools" / "servobus"
BUILD = REPO / "build" / "host"
PROGRAM = """#include "servobus/servobus.h"
void set_up(sb_bus *bus, sb_loop *loop, sb_stream *s, sb_transport t, const uint8_t *ids);
void set_up(sb_bus *bus, sb_loop *loop, sb_stream *s, sb_transport t, const uint8_t *ids)
{
    sb_bus_init(bus, t, 1000000u);
    (void)sb_loop_init(loop, bus, ids, 2, 20);
    (void)sb_stream_init(s, ids, 2, 20);
}
"""


def _symbols(path, *flags) -> set:
    out = subprocess.run(["nm", *flags, str(path)], capture_output=True, text=True, check=True).stdout
    return {line.split()[-1] for line in out.splitlines() if line.strip() and not line.endswith(":")}


def test_a_program_of_another_sb_max_servos_does_not_link_with_the_library(tmp_path):
    library = BUILD / "tools" / "servobus" / "libservobus.a"
    if not library.exists():
        pytest.fail(f"{library} is not built: cmake --preset host && cmake --build --preset host")
    cc = shutil.which("cc") or shutil.which("gcc")
    (tmp_path / "app.c").write_text(PROGRAM)
    subprocess.run([cc, "-std=c99", "-c", "-DSB_MAX_SERVOS=4", f"-I{SERVOBUS / 'include'}",
                    f"-I{BUILD / 'generated_servobus'}", "app.c", "-o", "app.o"], cwd=tmp_path, check=True)
    wanted = _symbols(tmp_path / "app.o", "-u")
    defined = _symbols(library, "--defined-only")
    names = ("sb_bus_init_max_{}", "sb_loop_init_max_{}", "sb_stream_init_max_{}")
    assert {n.format(4) for n in names} <= wanted, wanted
    assert {n.format(32) for n in names} <= defined and not {n.format(4) for n in names} & defined
