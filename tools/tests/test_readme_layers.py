"""The README's table of layers (top to bottom) agrees with the layer list
scripts/check_layers.py enforces: every firmware layer has a row, and no
row's layer may include one drawn above it. A second copy of the order
that disagreed with the checker's (motion and the services below the
register file they include) is what this stops."""
import importlib.util
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def checker():
    spec = importlib.util.spec_from_file_location("check_layers", ROOT / "scripts/check_layers.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def layer_of(folders, folder: str):
    folder = folder.rstrip("/")
    return next((layer for prefix, layer in folders if folder == prefix or folder.startswith(prefix + "/")), None)


def readme_rows(folders) -> list:
    """[(row name, {layers of its folders})] of the table, top to bottom; the
    schema's row and those outside the firmware (tests, tools) have none."""
    text = (ROOT / "README.md").read_text()
    table = text[text.index("| layer | folder | what it does |"):]
    rows = []
    for line in table.splitlines()[2:]:
        if not line.startswith("|"):
            break
        name, folder_cell = [c.strip() for c in line.strip("|").split("|")[:2]]
        layers = {layer_of(folders, f) for f in re.findall(r"`([^`]+)`", folder_cell)}
        rows.append((name, layers - {None}))
    return rows


def misdrawn(rows, layers) -> list:
    """Each row whose layer includes a layer drawn above it."""
    wrong = []
    for k, (name, mine) in enumerate(rows):
        above = set().union(set(), *(l for _, l in rows[:k]))
        for layer in mine:
            allowed = layers[layer]
            if allowed is not None and allowed & above:
                wrong.append(f"{name} ({layer}) includes {sorted(allowed & above)}, drawn above it")
    return wrong


def test_the_readme_draws_the_layers_the_checker_enforces():
    c = checker()
    rows = [(name, layers) for name, layers in readme_rows(c.FOLDERS) if name != "the protocol, declared"]
    drawn = set().union(*(layers for _, layers in rows))
    assert drawn == set(c.LAYERS), f"layers with no row: {set(c.LAYERS) - drawn}; rows of none: {drawn - set(c.LAYERS)}"
    assert not misdrawn(rows, c.LAYERS)


def test_a_row_drawn_above_what_includes_it_is_named():
    """The README's earlier order: the register file above motion and the
    services, which include it."""
    c = checker()
    rows = [("dispatch", {"dispatch"}), ("wire", {"wire"}), ("register file", {"registers"}),
            ("motion", {"motion"}), ("services", {"storage", "sensors", "protection"})]
    assert sorted(misdrawn(rows, c.LAYERS)) == [
        "motion (motion) includes ['registers'], drawn above it",
        "services (protection) includes ['registers'], drawn above it",
        "services (storage) includes ['registers'], drawn above it",
    ]
