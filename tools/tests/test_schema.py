"""protocol/servo_schema/*.toml declare the protocol once: the firmware's tables,
servoctl's and the reference (docs/protocol.md, protocol-packets.md) are
made from it. The reference is committed and must be what the schema makes
now; a schema that cannot be
is refused with a sentence that says why; and a new data item and a new
packet need the schema and the packet's handler, nothing else."""
import importlib.util
import os
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

import servo_schema as schema

ROOT = Path(__file__).resolve().parents[2]
GEN = ROOT / "scripts" / "gen_protocol.py"


def test_the_protocol_reference_is_what_the_schema_makes():
    done = subprocess.run([sys.executable, str(GEN), "docs", str(ROOT / "docs"), "--check"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def _with(text, old: str, new: str):
    """text (a file's, or the schema's files') with old, where it first is, made new."""
    if not isinstance(text, str):
        text = list(text)
        k = next(k for k, one in enumerate(text) if old in one)
        return text[:k] + [_with(text[k], old, new)] + text[k + 1:]
    assert old in text
    return text.replace(old, new, 1)


SCHEMA = [path.read_text(encoding="utf-8") for path in schema.files()]


NEW_ITEM = ('\n[[item]]\nid = 54\narea = "user"\nname = "test_hold_ms"\nfield = "test_hold_ms"\nsize = 2\n'
            'access = "read-write"\nmin = 0\nmax = 1000\nfactory = 250\nunit = "ms"\n'
            'what = "an item added by test_schema"\n')
LAST_ITEM = "what = \"shifts the zero every angle read and written refers to\"\n"

@pytest.mark.parametrize("broken, said", [
    (_with(SCHEMA, "code = 2\n", "code = 1\n"), "two packet codes 1"),
    (_with(SCHEMA, 'flags = ["addressed", "answers", "query"]', 'flags = ["adressed"]'), "flags"),
    (_with(SCHEMA, "code = 0x41\n", "code = 0x47\n"), "consecutive codes"),
    (_with(SCHEMA, 'factory = 3000\nunit = "ms"', 'factory = 70000\nunit = "ms"'), "soft_start_time"),
    (_with(SCHEMA, "id = 33\n", "id = 60\n"), "consecutive IDs from 32"),
    (_with(SCHEMA, 'access = "reserved"', 'access = "hidden"'), "access one of"),
    (_with(SCHEMA, "length = [3, 6]\n", "length = [6, 3]\n"), "length is a number"),
    (_with(SCHEMA, 'request = [["id", "u8", "", "servo ID"]]', 'request = [["id", "u9", "", "x"]]'), "type"),
    (_with(SCHEMA, LAST_ITEM, LAST_ITEM + "\n[[item]]\nid = 54\n"), "no area"),
    (_with(SCHEMA, LAST_ITEM, LAST_ITEM + NEW_ITEM),
     "ReadBatchData.*an answer of 35 bytes does not fit the frame's answer_content_max"),
    ("[frame\n", "not TOML"),
    (_with(SCHEMA, "{min = -1800, max = 1800,", "{min = -40000, max = 1800,"), "range needs -32768 <= min"),
    (_with(SCHEMA, 'max = 1, out = "refuse"}', 'max = 1, out = "wrap"}'), "out is clamp or refuse"),
    (_with(SCHEMA, '{min = 0, max = 16}', '{min = 0, max = 16, out = "clamp"}'), "a range is {max, min}"),
    (_with(SCHEMA, '"cruise speed", {min = 10,', '"cruise speed", {min = 11,'),
     "field target_velocity ranges other than in"),
])
def test_a_schema_that_cannot_be_is_refused_with_its_reason(broken, said):
    with pytest.raises(schema.SchemaError, match=said):
        schema.parse(broken)


NEW_PACKET = '''
[[packet]]
code = 0x47
name = "Echo"
c = "ECHO"
source = "firmware"
table = "firmware"
flags = ["addressed", "answers", "query"]
length = 2
handler = "echo"
what = "answers its byte back (added by test_schema)"
request = [["id", "u8", "", "servo ID"], ["value", "u8", "", "any"]]
answer = [["id", "u8", "", "servo ID"], ["value", "u8", "", "the request's"]]
'''

NEW_HANDLER = '''
enum packet_outcome handle_echo(const struct packet_call *c, struct response *r)
{
    r->content[1] = c->content[1];
    r->length = 2;
    return OUTCOME_OK;
}
'''

# In the copy of the tree, with its own servo_sim: the item answers its
# factory value through ReadData and config dump, the packet its byte.
CLIENT = '''
import sys
from servoctl import protocol as p, registers
from servoctl.cli import main
from servoctl.sim import Simulator
with Simulator(ids=[1]) as sim:
    with sim.bus() as bus:
        answer = bus.request(p.ECHO, p.encode_request(p.ECHO, 1, 0x5A))
        assert p.decode_answer(p.ECHO, answer) == (1, 0x5A), "Echo"
        assert bus.request(p.READ_DATA, bytes([1, 54])) == bytes([1, 54, 250, 0]), "item 54"
        assert len(bus.request(p.READ_BATCH, bytes([1]))) == 1 + registers.USER_AREA_SIZE == 35
    sys.exit(main(["--port", sim.url, "config", "dump", "1"], clock=sim.clock_s))
'''


def test_a_new_item_and_a_new_packet_need_the_schema_and_the_handler_only(tmp_path):
    """A copy of the tree, changed in two places: the schema gains user item
    54 and packet 0x47 (and room for the batch packets, which grow with the
    user area), and handlers_data.c gains handle_echo(). Its
    servo_sim builds and answers both, its servoctl knows both (config dump
    lists the item), and its docs/protocol.md describes both."""
    tree = tmp_path / "tree"
    with tarfile.open(tmp_path / "tree.tar", "w") as tar:
        for name in ("CMakeLists.txt", "CMakePresets.json", "cmake", "firmware", "bootloader", "services", "hal",
                     "motion", "protocol", "registers", "scripts", "tests", "tools"):
            tar.add(ROOT / name, arcname=name,
                    filter=lambda t: None if "__pycache__" in t.name or t.name.endswith(".egg-info") else t)
    with tarfile.open(tmp_path / "tree.tar") as tar:
        tar.extractall(tree, filter="data")
    folder = tree / "protocol/servo_schema"
    items, packets, frame = (folder / "items_maker.toml", folder / "packets_firmware.toml", folder / "frame.toml")
    items.write_text(_with(items.read_text(encoding="utf-8"), LAST_ITEM, LAST_ITEM + NEW_ITEM), encoding="utf-8")
    packets.write_text(packets.read_text(encoding="utf-8") + NEW_PACKET, encoding="utf-8")
    # The batch packets grow with the user area: the frame buffers with them.
    text = _with(_with(frame.read_text(encoding="utf-8"), "request_content_max = 34", "request_content_max = 35"),
                 "answer_content_max = 34", "answer_content_max = 35")
    frame.write_text(text, encoding="utf-8")
    handlers = tree / "protocol/handlers_data.c"
    handlers.write_text(handlers.read_text(encoding="utf-8") + NEW_HANDLER, encoding="utf-8")

    build = tree / "build/sim"
    for argv in (["cmake", "-S", str(tree), "-B", str(build), "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release"],
                 ["cmake", "--build", str(build), "--target", "servo_sim"]):
        done = subprocess.run(argv, capture_output=True, text=True)
        assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    sim = next(build.rglob("servo_sim"))

    env = dict(os.environ, SERVO_SIM=str(sim), PYTHONPATH=os.pathsep.join([str(tree / "tools"), str(tree / "protocol")]))
    done = subprocess.run([sys.executable, "-c", CLIENT], cwd=tree / "tools", env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "test_hold_ms" in done.stdout and "250" in done.stdout, done.stdout

    docs = tree / "docs"
    docs.mkdir(exist_ok=True)
    subprocess.run([sys.executable, str(tree / "scripts/gen_protocol.py"), "docs", str(docs)], check=True)
    text = (docs / "protocol.md").read_text(encoding="utf-8")
    assert "| 0x47 (71) | [Echo](protocol-packets.md#0x47-echo) |" in text
    assert "| 54 | test_hold_ms | 2 | u16 | read-write | 0..1000 | 250 | ms |" in text
    assert "## 0x47 Echo" in (docs / "protocol-packets.md").read_text(encoding="utf-8")
    shutil.rmtree(build)


_spec = importlib.util.spec_from_file_location("gen_protocol", GEN)
gen_protocol = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(gen_protocol)


def test_a_request_fields_range_is_the_firmwares_and_servoctls():
    """The range is the schema's: the C header the firmware clamps and
    refuses by, servoctl's checks and the reference's words come from it."""
    from servoctl import protocol as p
    s = schema.load()
    header = gen_protocol.field_ranges_h(s)
    assert "#define FIELD_MOVE_MULTI_TURN_ANGLE_MIN (-3686400) /* MoveOnMultiTurnAngleMode's angle: clamp */" in header
    assert "#define FIELD_DRIVE_DUTY_TIME_MAX 10000u\n" in header
    assert p.field_range(p.STREAM_SETPOINT, "velocity") == (-7500, 7500)
    assert p.field_range(p.ANGLE, "interval") == (0, 65535)  # no range given: the type's
    assert "| angle | i32 | 0.1deg | target; -3686400..3686400, clamped |" in \
        (ROOT / "docs/protocol-packets.md").read_text(encoding="utf-8")


# What the schema says once, and no source says again: the ranges of the
# moves' fields, and the status bits as masks.
ONCE = {"3686400": ("motion", "protocol", "tools/servoctl"), "4096000": ("motion", "protocol", "tools/servoctl"),
        "7500": ("motion", "protocol", "tools/servoctl"), "1 << ": ("tools/servoctl/outcome.py",),
        "= 1, 2, 4, 8, 16": ("tools/tests/integration/test_spec.py",)}


def test_the_schemas_numbers_are_written_nowhere_else():
    found = []
    for text, places in ONCE.items():
        for place in places:
            paths = [ROOT / place] if place.endswith(".py") else \
                [f for f in (ROOT / place).rglob("*") if f.suffix in (".c", ".h", ".py")]
            found += [f"{path.relative_to(ROOT)}: {text}" for path in paths
                      if text in path.read_text(encoding="utf-8")]
    assert found == []
