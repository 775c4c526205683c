"""scripts/check_layers.py finds what it is there to find: a lower layer
including a higher one, a circle of modules or of servoctl imports, and a
long file; and it passes the tree as it is."""
import importlib.util
from pathlib import Path

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
    breaches, graph = check_layers.check(ROOT)
    assert breaches == []
    assert len(graph) > 100  # it read the firmware, not an empty folder


def test_a_lower_layer_including_a_higher_one_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "protocol/wire/frame_rx.c", '#include "motion/motion.h"\n')
    breaches, _ = check_layers.check(root)
    assert breaches == ["layer: protocol/wire/frame_rx.c (wire) includes "
                        "motion/include/motion/motion.h (motion)"]


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


def test_a_long_file_is_found(tmp_path):
    root = tree(tmp_path)
    write(root, "tools/servoctl/cli.py", "pass\n" * 551)
    write(root, "motion/motion.c", "\n" * 700)  # the one hub spared
    breaches, _ = check_layers.check(root)
    assert breaches == ["long file: tools/servoctl/cli.py has 551 lines (limit 550)"]
