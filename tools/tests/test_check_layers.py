"""scripts/check_layers.py finds what it is there to find: a lower layer
including a higher one, a circle of modules (by includes, or by the symbols
their objects define and use) or of servoctl imports, servoctl's library
importing its command line, and a long file; and
it passes the tree as it is."""
import importlib.util
import json
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("check_layers", ROOT / "scripts/check_layers.py")
check_layers = importlib.util.module_from_spec(spec)
spec.loader.exec_module(check_layers)


def write(root, rel, text):
    path = root / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def tree(tmp_path):
    write(tmp_path, "registers/include/registers/registers.h", "struct registers;\n")
    write(tmp_path, "motion/include/motion/motion.h", '#include "registers/registers.h"\n')
    write(tmp_path, "protocol/wire/include/protocol/wire.h", '#include "registers/registers.h"\n')
    write(tmp_path, "tools/servoctl/servo.py", "from . import protocol\n")
    write(tmp_path, "tools/servoctl/protocol.py", "import struct\n")
    return tmp_path


def test_a_clean_tree_passes(tmp_path):
    breaches, _ = check_layers.check(tree(tmp_path))
    assert breaches == []


def test_the_project_passes():
    # The host build's objects when there is one (the test command builds
    # it before pytest and checks them itself too).
    build = ROOT / "build/host"
    breaches, graph = check_layers.check(ROOT, build if (build / "compile_commands.json").is_file() else None)
    assert breaches == []
    assert len(graph) > 100  # it read the firmware, not an empty folder


@pytest.mark.skipif(shutil.which("gcc") is None or shutil.which("nm") is None, reason="needs gcc and nm")
def test_a_circle_of_symbols_is_found(tmp_path):
    """No include shows it (each file declares what it calls): a.c calls
    b(), b.c calls a(). c.c calls a() without being called: no circle."""
    root = tree(tmp_path)
    write(root, "motion/a.c", "void b(void);\nvoid a(void);\nvoid a(void) { b(); }\n")
    write(root, "motion/b.c", "void a(void);\nvoid b(void);\nvoid b(void) { a(); }\n")
    write(root, "motion/c.c", "void a(void);\nvoid c(void);\nvoid c(void) { a(); }\n")
    build = root / "build"
    build.mkdir()
    commands = []
    for name in "abc":
        command = f"gcc -c -o {name}.o {root}/motion/{name}.c"
        subprocess.run(command.split(), cwd=build, check=True)
        commands.append({"directory": str(build), "command": command, "file": f"{root}/motion/{name}.c"})
    (build / "compile_commands.json").write_text(json.dumps(commands))
    assert check_layers.check(root)[0] == []  # the includes alone see nothing
    breaches, _ = check_layers.check(root, build)
    assert breaches == ["circle of symbols: motion/a <-> motion/b"]


@pytest.mark.skipif(shutil.which("gcc") is None or shutil.which("nm") is None, reason="needs gcc and nm")
def test_a_circle_between_servobus_files_is_found_generated_ones_too(tmp_path):
    """servobus is no firmware layer, and its generated files are in the
    build: a circle between a source and a generated file counts."""
    root = tree(tmp_path)
    generated = root / "build/generated_servobus/servobus"
    write(root, "tools/servobus/src/sb_bus.c", "void call(void);\nvoid send(void);\nvoid send(void) { call(); }\n")
    write(generated, "sb_calls.c", "void send(void);\nvoid call(void);\nvoid call(void) { send(); }\n")
    build = root / "build"
    commands = []
    for name, source in (("bus", root / "tools/servobus/src/sb_bus.c"), ("calls", generated / "sb_calls.c")):
        command = f"gcc -c -o {name}.o {source}"
        subprocess.run(command.split(), cwd=build, check=True)
        commands.append({"directory": str(build), "command": command, "file": str(source)})
    (build / "compile_commands.json").write_text(json.dumps(commands))
    breaches, _ = check_layers.check(root, build)
    assert breaches == ["circle of symbols: build/generated_servobus/servobus/sb_calls <-> tools/servobus/src/sb_bus"]


def test_a_lower_layer_including_a_higher_one_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "protocol/wire/frame_rx.c", '#include "motion/motion.h"\n')
    breaches, _ = check_layers.check(root)
    assert breaches == ["layer: protocol/wire/frame_rx.c (wire) includes "
                        "motion/include/motion/motion.h (motion)"]


@pytest.mark.parametrize("rel, text", [
    ("protocol/wire/frame_rx.c", '/* a comment first */ #include "motion/motion.h"\n'),
    ("protocol/wire/frame_rx.c", '%:include "motion/motion.h"\n'),  # the digraph
    ("protocol/wire/frame_rx.inc", '#include "motion/motion.h"\n'),  # a file included, not compiled
])
def test_an_include_in_any_form_the_compiler_takes_is_found(tmp_path, rel, text):
    root = tree(tmp_path)
    write(root, rel, text)
    write(root, "protocol/wire/frame_rx_hidden.c", '/*\n#include "motion/motion.h"\n*/\n')  # not an include
    breaches, _ = check_layers.check(root)
    assert breaches == [f"layer: {rel} (wire) includes motion/include/motion/motion.h (motion)"]


def test_a_job_reaching_the_application_hub_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "firmware/app/servo_state.h", "struct servo { int tick; };\n")
    write(root, "firmware/app/servo.c", '#include "app/servo_state.h"\n')
    write(root, "firmware/app/servo_turns.c", "struct servo_tx;\n")
    assert check_layers.check(root)[0] == []  # the main loop may; a job's own struct is no breach
    write(root, "firmware/app/servo_store.c", '#include "app/servo_state.h"\n')
    write(root, "firmware/app/servo_safety.c", "void safety_tend(struct servo *s);\n")
    # Through another header of the application's, and a typedef: a job still.
    write(root, "firmware/app/hub_view.h", '#include "app/servo_state.h"\n')
    write(root, "firmware/app/leds.c", '#include "app/hub_view.h"\n')
    write(root, "firmware/app/hub_fwd.h", "typedef struct servo hub_t; /* struct servo_tx is another */\n")
    breaches, _ = check_layers.check(root)
    assert breaches == [
        "hub: firmware/app/hub_fwd.h names struct servo: a job is handed what it needs",
        "hub: firmware/app/hub_view.h reaches firmware/app/servo_state.h: a job is handed what it needs",
        "hub: firmware/app/leds.c reaches firmware/app/servo_state.h: a job is handed what it needs",
        "hub: firmware/app/servo_safety.c names struct servo: a job is handed what it needs",
        "hub: firmware/app/servo_store.c reaches firmware/app/servo_state.h: a job is handed what it needs"]


@pytest.mark.parametrize("line,said", [
    ("#include <protection/winding.h>", "include: services/sensors/ntc.c includes <protection/winding.h>: "
                                        "a project header, named as the system's"),
    ('#define HUB_H "protection/winding.h"\n#include HUB_H', "include: services/sensors/ntc.c includes HUB_H: "
                                                           "not a name, so no layer is known"),
    ('#include "hal/../../services/protection/winding.h"', 'include: services/sensors/ntc.c includes '
                                                          '"hal/../../services/protection/winding.h": a relative '
                                                          'path hides the layer it reaches'),
])
def test_an_include_that_hides_its_layer_is_found(tmp_path, line, said):
    """An include in <>, by a macro, or through "..": the layer it reaches
    is checked or named, never passed unseen. A comment inside the
    directive changes nothing."""
    root = tree(tmp_path)
    write(root, "services/protection/winding.h", "int winding(void);\n")
    write(root, "hal/include/hal/hal_port.h", "struct hal_port;\n")
    write(root, "services/sensors/ntc.c", "#include <stdint.h>\n#include /* the port */ \"hal/hal_port.h\"\n")
    assert check_layers.check(root)[0] == []
    write(root, "services/sensors/ntc.c", line + "\n")
    breaches = check_layers.check(root)[0]
    assert said in breaches, breaches
    if line.startswith("#include <"):  # and the layer it reaches is judged too
        assert "layer: services/sensors/ntc.c (sensors) includes services/protection/winding.h (protection)" \
            in breaches, breaches


def test_a_firmware_file_in_no_layers_folder_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "tools/vboard/native/model.c", "int m;\n")  # the PC tools': their own rules
    assert check_layers.check(root)[0] == []
    write(root, "hal/extra.c", '#include "app/servo_state.h"\n')
    assert check_layers.check(root)[0] == [
        "layer: hal/extra.c is in no layer's folder (scripts/check_layers.py, FOLDERS)"]


def test_a_circle_of_modules_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "firmware/boards/sim/a.h", "void a(void);\n")
    write(root, "firmware/boards/sim/b.h", "void b(void);\n")
    write(root, "firmware/boards/sim/a.c", '#include "a.h"\n#include "b.h"\n')
    write(root, "firmware/boards/sim/b.c", '#include "b.h"\n#include "a.h"\n')
    breaches, _ = check_layers.check(root)
    assert breaches == ["circle of modules: firmware/boards/sim/a <-> firmware/boards/sim/b"]


def test_a_circle_of_servoctl_imports_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "tools/servoctl/protocol.py", "from .servo import Servo\n")
    breaches, _ = check_layers.check(root)
    assert breaches == ["circle of imports in servoctl: protocol -> servo"]


@pytest.mark.parametrize("rel,text,what", [
    ("tools/servoctl/units.py", "from .cli import app\n", "servoctl.cli.app"),
    ("tools/servoctl/group.py", "def run():\n    from .cli.cmd_bus import cmd_scan\n", "servoctl.cli.cmd_bus"),
    ("tools/servoctl/units.py", "from . import ui\n", "servoctl.ui"),
    ("tools/servoctl/stream.py", "import servoctl.cli\n", "servoctl.cli"),
    ("tools/servoctl/units.py", "from vboard import board\n", "vboard"),
    ("tools/servoctl/sub/thing.py", "from ..cli import args\n", "servoctl.cli.args"),
    ("tools/servoctl/units.py", "import importlib\nimportlib.import_module('servoctl.cli.app')\n", "servoctl.cli.app"),
    ("tools/servoctl/units.py", "__import__('vboard', fromlist=['x'])\n", "vboard"),
])
def test_a_library_module_importing_the_command_line_is_found(tmp_path, rel, text, what):
    """servoctl's library (all but servoctl.cli and servoctl.ui) imports
    neither those nor the virtual boards, at the top or in a function;
    the command line and the ui import the library and each other."""
    root = tree(tmp_path)
    write(root, "tools/servoctl/cli/__init__.py", "from .. import protocol\n")
    write(root, "tools/servoctl/cli/app.py", "from ..servo import Servo\nfrom . import args\n")
    write(root, "tools/servoctl/cli/cmd_bus.py", "from ..ui import worker\n")
    write(root, "tools/servoctl/cli/args.py", "import servoctl.protocol\n")
    write(root, "tools/servoctl/ui/__init__.py", "")
    write(root, "tools/servoctl/ui/worker.py", "from ..cli import args\nimport vboard\n")
    assert check_layers.check(root)[0] == []
    write(root, rel, text)
    breaches, _ = check_layers.check(root)
    assert len(breaches) == 1 and breaches[0].startswith(f"library import: {rel} imports {what}: "), breaches


@pytest.mark.parametrize("text,said", [
    ("exec('from servoctl import cli')\n", "exec"),
    ("import importlib\nname = 'servoctl.' + 'cli'\nimportlib.import_module(name)\n",
     "import_module of a computed name"),
])
def test_a_library_module_running_code_from_a_string_is_found(tmp_path, text, said):
    """What exec or an import by a computed name brings no reader can see."""
    root = tree(tmp_path)
    write(root, "tools/servoctl/units.py", text)
    assert check_layers.check(root)[0] == [
        f"library import: tools/servoctl/units.py runs code from a string ({said}): its imports could not be checked"]


def test_a_circle_through_the_command_line_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "tools/servoctl/cli/__init__.py", "")
    write(root, "tools/servoctl/cli/app.py", "from . import cmd_ui\n")
    write(root, "tools/servoctl/cli/cmd_ui.py", "def cmd_ui():\n    from ..ui import worker\n")
    write(root, "tools/servoctl/ui/__init__.py", "")
    write(root, "tools/servoctl/ui/worker.py", "from ..cli.app import run_command\n")
    breaches, _ = check_layers.check(root)
    assert breaches == ["circle of imports in servoctl: cli.app -> cli.cmd_ui -> ui.worker"]


def test_a_long_file_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "tools/servoctl/cli.py", "pass\n" * 401)
    write(root, "motion/motion.c", "\n" * 400)
    breaches, _ = check_layers.check(root)
    assert breaches == ["long file: tools/servoctl/cli.py has 401 lines (limit 400)"]


def test_a_generated_file_may_be_long(tmp_path):
    """Only when the generator it names exists: a line anyone can write is
    no pass. A linker script and the CI's script count too."""
    root = tree(tmp_path)
    write(root, "docs/protocol.md", "# x\n\n<!-- Generated by scripts/gen.py: do not edit. -->\n" + "\n" * 500)
    assert check_layers.check(root)[0] == ["long file: docs/protocol.md has 503 lines (limit 400)"]
    write(root, "scripts/gen.py", "print()\n")
    assert check_layers.check(root)[0] == []
    write(root, "docs/protocol.md", "# x\n" + "\n" * 500)
    write(root, "hal/ports/stm32_common/linker/big.ld", "\n" * 401)
    write(root, ".ci/run", "\n" * 401)
    assert sorted(check_layers.check(root)[0]) == [
        "long file: .ci/run has 401 lines (limit 400)",
        "long file: docs/protocol.md has 501 lines (limit 400)",
        "long file: hal/ports/stm32_common/linker/big.ld has 401 lines (limit 400)"]


def test_an_include_that_names_no_layer_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "services/storage/crc32.h", "int crc32(void);\n")
    write(root, "services/storage/crc32.c", '#include "crc32.h"\n')  # beside it, but bare
    write(root, "services/storage/save.c", '#include "storage/crc32.h"\n')
    breaches, _ = check_layers.check(root)
    assert breaches == ['include: services/storage/crc32.c includes "crc32.h", which names no layer']


def test_a_board_includes_its_own_files_by_name(tmp_path):
    """A copied board folder is a new board: its board.h is its own."""
    root = tree(tmp_path)
    for board in ("stm32f103", "my_servo"):
        write(root, f"firmware/boards/{board}/board.h", "#define BOARD_ID 1\n")
        write(root, f"firmware/boards/{board}/main.c", '#include "board.h"\n')
    breaches, graph = check_layers.check(root)
    assert breaches == []
    assert graph["firmware/boards/my_servo/main.c"] == ["firmware/boards/my_servo/board.h"]


def test_two_headers_of_one_name_are_found(tmp_path):
    root = tree(tmp_path)
    write(root, "hal/ports/stm32f1/port_uart.h", "void f1(void);\n")
    write(root, "hal/ports/stm32f0/port_uart.h", "void f0(void);\n")
    breaches, _ = check_layers.check(root)
    assert breaches == ["header name: port_uart.h is hal/ports/stm32f0/port_uart.h, "
                        "hal/ports/stm32f1/port_uart.h"]


def test_the_build_importing_from_tools_is_found(tmp_path):
    """The Python the firmware's build runs (a script a CMake file names,
    and the modules of the tree it imports) imports no package of tools/,
    puts no tools/ folder on its path, and needs only the standard library;
    and the build runs no Python module by name nor with tools/ on its path
    (before: the image step ran servoctl.image)."""
    root = tree(tmp_path)
    write(root, "tools/servoctl/__init__.py", "")
    write(root, "CMakeLists.txt", "add_custom_command(OUTPUT x COMMAND ${Python3_EXECUTABLE} "
                                  "${PROJECT_SOURCE_DIR}/scripts/gen.py c out)\n")
    write(root, "protocol/reader/__init__.py", "import tomllib\n")
    write(root, "scripts/gen.py", "import sys\nsys.path.insert(0, 'protocol')\nimport reader\n")
    assert check_layers.check(root)[0] == []
    write(root, "protocol/reader/__init__.py", "import tomllib\nimport yaml\nfrom servoctl import errors\n")
    write(root, "scripts/gen.py", "import sys\nsys.path.insert(0, 'tools')\nimport reader\n")
    assert sorted(check_layers.check(root)[0]) == [
        "build import: protocol/reader/__init__.py imports servoctl, from tools/",
        "build import: protocol/reader/__init__.py imports yaml, not in the standard library",
        "build import: scripts/gen.py puts tools/ on its path"]
    write(root, "cmake/image.cmake", "add_custom_command(TARGET x POST_BUILD COMMAND ${CMAKE_COMMAND} -E env "
                                     "PYTHONPATH=${PROJECT_SOURCE_DIR}/tools ${Python3_EXECUTABLE} -m servoctl.image)\n")
    assert sorted(check_layers.check(root)[0])[:2] == [
        "build import: cmake/image.cmake runs ${Python3_EXECUTABLE} -m servoctl.image",
        "build import: cmake/image.cmake runs PYTHONPATH=${PROJECT_SOURCE_DIR}/tools"]


def test_the_builds_python_is_followed_however_it_is_named(tmp_path):
    """A script named from the source tree's root or the CMake file's own
    folder, a module it imports relatively, one it imports by name."""
    root = tree(tmp_path)
    write(root, "tools/servoctl/__init__.py", "")
    write(root, "gen/CMakeLists.txt", "add_custom_command(OUTPUT x COMMAND ${Python3_EXECUTABLE} "
                                      "${CMAKE_SOURCE_DIR}/scripts/a.py COMMAND ${Python3_EXECUTABLE} "
                                      "${CMAKE_CURRENT_LIST_DIR}/b.py)\n")
    write(root, "scripts/a.py", "import importlib\nimportlib.import_module('servoctl.units')\n")
    write(root, "gen/b.py", "from . import helper\n")
    write(root, "gen/helper.py", "import numpy\n")
    assert sorted(check_layers.check(root)[0]) == [
        "build import: gen/helper.py imports numpy, not in the standard library",
        "build import: scripts/a.py imports servoctl, from tools/"]


def test_a_long_schema_line_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "protocol/servo_schema/items.toml", "# " + "x" * 118 + "\n")
    write(root, "protocol/control_port.toml", "# short\n")
    assert check_layers.check(root)[0] == []
    write(root, "protocol/control_port.toml", "# short\n# " + "x" * 119 + "\n")
    assert check_layers.check(root)[0] == [
        "long schema line: protocol/control_port.toml:2 has 121 characters (limit 120)"]


def test_a_lower_layer_using_a_higher_ones_symbols_is_found():
    """A declaration written out by hand passes the includes' rule; the
    symbols the objects use hold it (check_layers --objects)."""
    symbols = {"motion/controller": ["registers/data_table"], "protocol/dispatcher": ["motion/motion"],
               "firmware/boards/stm32f103/main": ["firmware/app/servo"], "tools/servobus/src/sb_bus": []}
    assert check_layers.symbol_layer_breaches(symbols) == []
    symbols["motion/controller"].append("firmware/app/servo_safety")
    assert check_layers.symbol_layer_breaches(symbols) == [
        "layer: motion/controller (motion) uses symbols of firmware/app/servo_safety (app)"]
