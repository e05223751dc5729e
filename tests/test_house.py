"""The house rules of issue 11 that a reader relies on: no import cycle inside the package (lazy
imports inside functions included), every file opens with a line on what it is for, and the
command line stays thin."""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "rockjit"
MODULES = sorted(p.stem for p in PKG.glob("*.py"))


def _imports(path):
    """The package's modules that ``path`` imports anywhere in its body."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level == 1 or (node.module or "").split(".")[0] == "rockjit":
                parts = (node.module or "").split(".")
                name = parts[0] if node.level == 1 else (parts[1] if len(parts) > 1 else "")
                if name:
                    found.add(name)
                else:  # from . import a, b
                    found |= {a.name for a in node.names if a.name in MODULES}
        elif isinstance(node, ast.Import):
            found |= {a.name.split(".")[1] for a in node.names
                      if a.name.startswith("rockjit.")}
    return found & set(MODULES) - {path.stem}


def _cycles(graph):
    """Every elementary cycle's node set (depth-first from each node)."""
    out = set()

    def walk(start, node, path):
        for nxt in graph.get(node, ()):
            if nxt == start:
                out.add(frozenset(path))
            elif nxt not in path and nxt > start:  # each cycle once, from its smallest node
                walk(start, nxt, path + [nxt])

    for m in graph:
        walk(m, m, [m])
    return out


def test_the_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == {frozenset("abc")}
    assert _cycles({"a": {"b"}, "b": set()}) == set()


def test_no_import_cycle_in_the_package():
    graph = {m: _imports(PKG / f"{m}.py") for m in MODULES if m not in ("__init__", "__main__")}
    assert graph["analysis"] and graph["cli"], "the import reader found nothing"
    cycles = _cycles(graph)
    assert not cycles, [sorted(c) for c in cycles]


@pytest.mark.parametrize("path", sorted(PKG.glob("*.py")) + sorted(ROOT.glob("benchmarks/*.py"))
                         + sorted(ROOT.glob("tests/*.py")), ids=lambda p: p.name)
def test_every_file_opens_with_what_it_is_for(path):
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
    assert doc and len(doc.splitlines()[0].split()) >= 3, f"{path.name}: no opening line"


def test_the_command_line_stays_thin():
    assert len((PKG / "cli.py").read_text(encoding="utf-8").splitlines()) <= 600
