"""The Python's layers, for check_layers.py: servoctl's module graph (its
circles are breaches there) and what its library may not import (its
command line, its ui, the virtual boards); and the Python the firmware's
build runs, which may import nothing from tools/ (the PC tools) and
nothing outside the standard library."""
import ast
import re
import sys

# A Python script a CMake file runs, from the project's or the file's folder.
BUILD_SCRIPT = re.compile(r"\$\{(PROJECT_SOURCE|CMAKE_SOURCE|CMAKE_CURRENT_SOURCE|CMAKE_CURRENT_LIST)_DIR\}/([\w/.-]+\.py)")
# A CMake file that runs Python with tools/ on its path, or a module by name (-m).
BUILD_MODULE = re.compile(r"PYTHONPATH=\S*/tools\b|\$\{Python3_EXECUTABLE\}\s+-m\s+[\w.]+|Interpreter\s+-m\s+[\w.]+")


# What servoctl's library (its modules but these) may not import: its command
# line, its ui (the command line's page), the virtual boards (a package of tools/).
NOT_LIBRARY, NOT_LIBRARY_PACKAGES = ("cli", "ui"), ("vboard",)


def _imported(here, node, modules):
    """What an import node in package here (["cli"]) brings: servoctl's
    modules by name ("cli.app"; a package's own module only when no name
    imported from it is one), another package as "/name"."""
    if isinstance(node, ast.Import):
        return [a.name[9:] if a.name.startswith("servoctl.") else "/" + a.name for a in node.names]
    if node.level == 0 and not (node.module or "").startswith("servoctl"):
        return ["/" + node.module] if node.module else []
    base = node.module[9:].split(".") if node.level == 0 and node.module != "servoctl" else [] if \
        node.level == 0 else here[:len(here) - node.level + 1] + (node.module.split(".") if node.module else [])
    names = [".".join(base + [a.name]) for a in node.names]
    return [n for n in names if n in modules] or [".".join(base)]


def _call_name(node):
    """A call's function as written: "import_module", "__import__", "exec"."""
    func = node.func if isinstance(node, ast.Call) else None
    return func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else None


def _imported_by_name(node):
    """What importlib.import_module("servoctl.cli") or __import__("vboard")
    brings, as _imported names it; a name not written out is _runs_strings'."""
    if _call_name(node) not in ("import_module", "__import__") or not node.args:
        return []
    name = node.args[0].value if isinstance(node.args[0], ast.Constant) else None
    if not isinstance(name, str):
        return []
    return [name[9:]] if name.startswith("servoctl.") else ["/" + name]


def _runs_strings(node):
    """exec, eval, or an import by a name the code computes: what a module
    brings that no reader can see."""
    call = _call_name(node)
    if call in ("exec", "eval"):
        return call
    if call in ("import_module", "__import__") and node.args and not isinstance(node.args[0], ast.Constant):
        return call + " of a computed name"
    return None


def python_imports(root, breaches=None):
    """servoctl's module graph: module -> the servoctl modules it imports
    (run or not: in a function too); breaches (a list) gets each import of
    the library's of NOT_LIBRARY."""
    pkg = root / "tools" / "servoctl"
    paths = {}
    for path in sorted(pkg.rglob("*.py")):
        parts = list(path.relative_to(pkg).with_suffix("").parts)
        paths[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    graph = {}
    for name, path in paths.items():
        here = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        deps, library = set(), name.split(".")[0] not in NOT_LIBRARY
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if library and breaches is not None and _runs_strings(node):
                breaches.append(f"library import: {path.relative_to(root).as_posix()} runs code from a "
                                f"string ({_runs_strings(node)}): its imports could not be checked")
            for dep in _imported([h for h in here if h], node, paths) if isinstance(
                    node, (ast.Import, ast.ImportFrom)) else _imported_by_name(node):
                top = dep.lstrip("/").split(".")[0]
                if library and breaches is not None and top in (
                        NOT_LIBRARY_PACKAGES if dep.startswith("/") else NOT_LIBRARY):
                    breaches.append(f"library import: {path.relative_to(root).as_posix()} imports "
                                    f"{top if dep.startswith('/') else 'servoctl.' + dep}: the library "
                                    f"must not need the command line, the ui or the virtual boards")
                if dep in paths and dep != name:
                    deps.add(dep)
        graph[name] = sorted(deps)
    return graph


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
            script = (root if where in ("PROJECT_SOURCE", "CMAKE_SOURCE") else cmake.parent) / name
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
            if _runs_strings(node):
                out.append(f"build import: {rel} runs code from a string ({_runs_strings(node)})")
            if isinstance(node, ast.ImportFrom) and node.level > 0:  # from . import x: beside it
                base = path.parent.joinpath(*[".."] * (node.level - 1), *(node.module or "").split("."))
                for a in node.names:
                    for f in (base / a.name / "__init__.py", (base / a.name).with_suffix(".py"),
                              base / "__init__.py", base.with_suffix(".py")):
                        if f.is_file():
                            todo.append(f.resolve())
                            break
                continue
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module] if isinstance(node, ast.ImportFrom) and node.module else \
                [node.args[0].value] if _imported_by_name(node) else []
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
