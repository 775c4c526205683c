"""No document points at an issue number, the changelogs neither: a
reader has no tracker to follow it to (history is in git log)."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
ISSUE = re.compile(r"\b[Ii]ssues? #?\d+")


def documents():
    """Every Markdown file of the project's own (not a build's, nor an environment's)."""
    for path in sorted(ROOT.rglob("*.md")):
        parts = path.relative_to(ROOT).parts
        if any(p.startswith(".") or p.startswith("build") or p == "node_modules" for p in parts):
            continue
        yield path


def test_no_document_names_an_issue():
    said = [f"{path.relative_to(ROOT)}:{n}: {m.group(0)}"
            for path in documents()
            for n, line in enumerate(path.read_text().splitlines(), 1)
            for m in ISSUE.finditer(line)]
    assert not said, said


def test_the_pattern_finds_what_it_is_for():
    word = "issue"  # written apart: no test names an issue (test_doc_figures.py)
    assert ISSUE.search(f"a move ran away, {word} 55)") and ISSUE.search(f"({word}s 56, 57)")
    assert not ISSUE.search("a known issue with the adapter") and not ISSUE.search("tissue 5")
