#!/usr/bin/env python3
"""The firmware's layers and circles, checked from its #include lines.

Each source folder is a layer; a layer may include only the layers below it
(LAYERS). No module (a .c with its .h) may reach itself through the
includes of others (a circle), nor through the symbols its object file
uses and the others define (`--objects BUILD`: a build's objects, read
with nm), nor may servoctl's modules through their imports; no file
people read (source, build files, documents) outside the tests may pass
LINE_LIMIT lines, nor a line of the protocol's schema SCHEMA_LINE_LIMIT
characters; and the Python the firmware's build runs imports nothing from
tools/ (the PC tools) and nothing outside the standard library.

Exit 1 with one line per breach; `--graph` prints the layer graph found."""
import argparse
import ast
import json
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# Folder (most specific first) -> layer.
FOLDERS = [
    ("hal/include", "hal"),
    ("hal/ports", "ports"),
    ("registers", "registers"),
    ("protocol/wire", "wire"),
    ("protocol", "dispatch"),
    ("motion", "motion"),
    ("firmware/storage", "storage"),
    ("firmware/sensors", "sensors"),
    ("firmware/protection", "protection"),
    ("firmware/bootloader", "bootloader"),
    ("firmware/runtime", "runtime"),
    ("firmware/startup", "startup"),
    ("firmware/app", "app"),
    ("firmware/boards", "boards"),
]

# Layer -> the layers it may include (below it).
LAYERS = {
    "hal": set(),
    "registers": set(),
    "runtime": set(),
    "startup": {"ports", "hal"},  # a family's vector table names its port's handlers
    "sensors": {"hal"},
    "wire": {"registers", "hal"},
    "storage": {"registers", "hal"},
    "motion": {"registers", "hal"},
    "protection": {"registers", "sensors", "hal"},
    "dispatch": {"wire", "registers", "motion", "hal"},
    "bootloader": {"wire", "storage", "registers", "hal"},
    "ports": {"hal", "runtime"},
    "app": {"dispatch", "wire", "registers", "motion", "storage", "sensors", "protection", "hal"},
    "boards": None,  # a board puts everything together
}

LINE_LIMIT = 550
# Source, build files and documents: every file a person reads.
TEXT_SUFFIXES = (".c", ".h", ".py", ".md", ".sh", ".cmake", ".txt", ".json", ".in", ".toml")

# The protocol's schema: its files and the simulators' control port.
SCHEMA_FILES = ("protocol/servo_schema/*.toml", "protocol/*.toml")
SCHEMA_LINE_LIMIT = 120
# A Python script a CMake file runs, from the project's or the file's folder.
BUILD_SCRIPT = re.compile(r"\$\{(PROJECT|CMAKE_CURRENT)_SOURCE_DIR\}/([\w/.-]+\.py)")
# A CMake file that runs Python with tools/ on its path, or a module by name (-m).
BUILD_MODULE = re.compile(r"PYTHONPATH=\S*/tools\b|\$\{Python3_EXECUTABLE\}\s+-m\s+[\w.]+|Interpreter\s+-m\s+[\w.]+")

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def layer_of(rel):
    for folder, layer in FOLDERS:
        if rel == folder or rel.startswith(folder + "/"):
            return layer
    return None


def sources(root):
    for path in sorted(root.rglob("*.[ch]")):
        rel = path.relative_to(root).as_posix()
        if rel.startswith(("build/", "tests/", ".")) or layer_of(rel) is None:
            continue
        yield rel


# Where an include's name is looked up: each layer's headers are named
# from one of these (firmware/storage/crc32.h is "storage/crc32.h").
INCLUDE_ROOTS = ("hal/include", "motion/include", "protocol/wire/include", "protocol/include",
                 "registers/include", "firmware", "hal", "tests", "")
BOARD_FOLDER = re.compile(r"^firmware/boards/[^/]+/")


def resolve(root, including, name):
    """The files an #include names: in a board's folder, its own files by
    bare name beside it (a copied folder is a new board); elsewhere the
    name from one of INCLUDE_ROOTS."""
    board = BOARD_FOLDER.match(including)
    if board and "/" not in name and (root / board.group(0) / name).is_file():
        return [board.group(0) + name]
    if "/" not in name:
        return []
    return [f"{r}/{name}" if r else name for r in INCLUDE_ROOTS if (root / r / name).is_file()]


def include_breaches(root):
    """Every include names its layer ("storage/crc32.h") and one file; no
    two headers share a name, but for a board's own (board.h in each)."""
    out = []
    files = [p for p in sorted(root.rglob("*")) if p.suffix in (".c", ".h", ".in") and p.is_file()]
    headers = {}
    for path in files:
        rel = path.relative_to(root).as_posix()
        if rel.startswith(("build/", ".")) or "/." in rel:
            continue
        if path.suffix == ".h" and not BOARD_FOLDER.match(rel):
            headers.setdefault(path.name, []).append(rel)
        for name in INCLUDE.findall(path.read_text(errors="replace")):
            found = resolve(root, rel, name)
            if "/" not in name and not found:
                out.append(f'include: {rel} includes "{name}", which names no layer')
            elif len(found) > 1:
                out.append(f'include: {rel} includes "{name}", which names {len(found)} files')
    for name, where in sorted(headers.items()):
        if len(where) > 1:
            out.append(f"header name: {name} is {', '.join(where)}")
    return out


def include_graph(root):
    graph = {}
    for rel in sources(root):
        text = (root / rel).read_text(errors="replace")
        graph[rel] = [t for n in INCLUDE.findall(text) for t in resolve(root, rel, n)[:1]]
    return graph


def circles(graph):
    """Every circle once, as a list of nodes (Tarjan's strongly connected
    components of more than one node, or a node that reaches itself)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, []):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1 or v in graph.get(v, []):
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def python_imports(root):
    """servoctl's module graph: module -> the servoctl modules it imports."""
    pkg = root / "tools" / "servoctl"
    graph = {}
    for path in sorted(pkg.glob("*.py")):
        tree = ast.parse(path.read_text(), str(path))
        deps = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                if node.level == 1 and node.module:
                    deps.add(node.module.split(".")[0])
                elif node.level == 1:
                    deps.update(a.name for a in node.names)
                elif node.module and node.module.startswith("servoctl."):
                    deps.add(node.module.split(".")[1])
            elif isinstance(node, ast.Import):
                deps.update(a.name.split(".")[1] for a in node.names if a.name.startswith("servoctl."))
        graph[path.stem] = sorted(d for d in deps if (pkg / f"{d}.py").is_file() and d != path.stem)
    return graph


def symbol_graph(root, build):
    """module -> the modules whose symbols its object uses, from a build's
    compile_commands.json and nm: each firmware source once (its first
    object), a module being a source without its suffix."""
    objects = {}
    for entry in json.loads((build / "compile_commands.json").read_text()):
        source = Path(entry["directory"], entry["file"]).resolve()
        try:
            rel = source.relative_to(root.resolve()).as_posix()
        except ValueError:
            continue
        if rel.startswith(("build/", "tests/")) or layer_of(rel) is None or rel in objects:
            continue
        # "output" is CMake 3.26's; before it, the command's -o.
        output = entry.get("output") or re.search(r"\s-o\s+(\S+)", entry["command"]).group(1)
        objects[rel] = Path(entry["directory"], output)
    defined, used = {}, {}
    for rel, obj in objects.items():
        module = rel.rsplit(".", 1)[0]
        out = subprocess.run(["nm", "-P", str(obj)], capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            name, kind = line.split()[:2]
            if kind == "U":
                used.setdefault(module, set()).add(name)
            elif kind.isupper():
                defined.setdefault(name, set()).add(module)
    graph = {}
    for module in {rel.rsplit(".", 1)[0] for rel in objects}:
        deps = set()
        for name in used.get(module, ()):
            deps.update(defined.get(name, ()))
        deps.discard(module)
        graph[module] = sorted(deps)
    return graph


def long_files(root):
    for path in sorted(root.rglob("*")):
        rel = path.relative_to(root).as_posix()
        if not path.is_file() or path.suffix not in TEXT_SUFFIXES:
            continue
        if rel.startswith(("build/", ".", "tests/", "tools/tests/")) or "/." in rel:
            continue
        n = len(path.read_text(errors="replace").splitlines())
        if n > LINE_LIMIT:
            yield rel, n


def long_schema_lines(root):
    for pattern in SCHEMA_FILES:
        for path in sorted(root.glob(pattern)):
            for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                if len(line) > SCHEMA_LINE_LIMIT:
                    yield path.relative_to(root).as_posix(), n, len(line)


def build_scripts(root, unnamed=None):
    """The Python scripts the firmware's build runs, named in its CMake files;
    unnamed (a list) gets where one runs Python it does not name by path."""
    out = set()
    for cmake in sorted(root.rglob("CMakeLists.txt")) + sorted(root.rglob("*.cmake")):
        rel = cmake.relative_to(root).as_posix()
        if rel.startswith(("build/", ".")) or "/." in rel:
            continue
        text = cmake.read_text(errors="replace")
        if unnamed is not None:
            unnamed += [f"build import: {rel} runs {m}" for m in BUILD_MODULE.findall(text)]
        for where, name in BUILD_SCRIPT.findall(text):
            script = (root if where == "PROJECT" else cmake.parent) / name
            if script.is_file():
                out.add(script.resolve())
    return sorted(out)


def build_import_breaches(root):
    """The build's scripts, and the modules of this tree they import, import
    no package of tools/ (servoctl, vboard: the build must not need the PC
    tool), put no tools/ folder on their path, and need nothing beyond the
    standard library."""
    tools = {p.parent.name for p in (root / "tools").glob("*/__init__.py")}
    out, seen = [], set()
    todo = list(build_scripts(root, out))
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        rel = path.relative_to(root.resolve()).as_posix()
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and node.value == "tools":
                out.append(f"build import: {rel} puts tools/ on its path")
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module else []
            for name in (n.split(".")[0] for n in names):
                local = [d / name for d in (path.parent, root / "protocol", root / "scripts")]
                found = [f for d in local for f in (d / "__init__.py", d.with_suffix(".py")) if f.is_file()]
                if name in tools:
                    out.append(f"build import: {rel} imports {name}, from tools/")
                elif found:
                    todo.append(found[0].resolve())
                elif name not in sys.stdlib_module_names:
                    out.append(f"build import: {rel} imports {name}, not in the standard library")
    return sorted(set(out))


def check(root, build=None):
    breaches = include_breaches(root)
    graph = include_graph(root)
    for rel, targets in graph.items():
        mine = layer_of(rel)
        allowed = LAYERS[mine]
        for t in targets:
            theirs = layer_of(t)
            if allowed is not None and theirs != mine and theirs not in allowed:
                breaches.append(f"layer: {rel} ({mine}) includes {t} ({theirs})")
    # A module is its .c and its .h: sim_bus.c calling into sim_servo.h
    # while sim_servo.c calls into sim_bus.h is a circle of modules.
    modules = {}
    for rel, targets in graph.items():
        deps = modules.setdefault(rel.rsplit(".", 1)[0], set())
        deps.update(t.rsplit(".", 1)[0] for t in targets)
    for m, deps in modules.items():
        deps.discard(m)
    for c in circles({m: sorted(d) for m, d in modules.items()}):
        breaches.append("circle of modules: " + " <-> ".join(c))
    if build is not None:
        for c in circles(symbol_graph(root, build)):
            breaches.append("circle of symbols: " + " <-> ".join(c))
    for c in circles(python_imports(root)):
        breaches.append("circle of imports in servoctl: " + " -> ".join(c))
    for rel, n in long_files(root):
        breaches.append(f"long file: {rel} has {n} lines (limit {LINE_LIMIT})")
    for rel, n, length in long_schema_lines(root):
        breaches.append(f"long schema line: {rel}:{n} has {length} characters (limit {SCHEMA_LINE_LIMIT})")
    breaches += build_import_breaches(root)
    return breaches, graph


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, default=ROOT)
    ap.add_argument("--graph", action="store_true", help="print which layer includes which")
    ap.add_argument("--objects", type=Path, metavar="BUILD",
                    help="also find circles of symbols in this build's objects (its compile_commands.json)")
    args = ap.parse_args()
    breaches, graph = check(args.root, args.objects)
    if args.graph:
        edges = sorted({(layer_of(a), layer_of(b)) for a, ts in graph.items() for b in ts
                        if layer_of(a) != layer_of(b)})
        for a, b in edges:
            print(f"{a} -> {b}")
    for b in breaches:
        print(b)
    files = len(graph)
    print(f"layers: {files} files, {len(breaches)} breaches")
    return 1 if breaches else 0


if __name__ == "__main__":
    sys.exit(main())
