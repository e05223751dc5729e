"""The house rules a reader relies on: no import cycle between the package's modules (lazy
imports inside functions included), none between its rooms either (a subpackage, or a module
of the package's top level: no import runs back up the house), the compiled engine below
storage and scheduling, the command line above everything it runs, no module of the package
for testing rockjit itself, and every file opening with a line on what it is for."""

import ast
from importlib.util import resolve_name
from pathlib import Path

import pytest

#: The repository (wherever in tests/ this file lies)
ROOT = next(p for p in Path(__file__).resolve().parents if (p / "pyproject.toml").is_file())
PKG = ROOT / "rockjit"


def _module_name(path):
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(p): p for p in sorted(PKG.rglob("*.py"))}


def _package(path):
    name = _module_name(path)
    return name if path.name == "__init__.py" else name.rpartition(".")[0]


def _imports(path):
    """The package's modules that ``path`` imports anywhere in its body (``from . import a``
    counts as importing ``a`` when ``a`` is a module, else the package)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            base = resolve_name("." * node.level + (node.module or ""), _package(path)) \
                if node.level else (node.module or "")
            if not base.startswith("rockjit"):
                continue
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                found.add(sub if sub in MODULES else base)
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("rockjit")}
    return {m for m in found if m in MODULES} - {_module_name(path)}


def _graph():
    # a package's face (its __init__) hands names on; the arrows that matter are between modules
    return {m: {d for d in _imports(p) if not MODULES[d].name == "__init__.py"}
            for m, p in MODULES.items() if p.name not in ("__init__.py", "__main__.py")}


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


def test_the_import_reader_resolves_relative_imports():
    graph = _graph()
    assert "rockjit._engine.integrate" in graph["rockjit._engine.kernel"]
    assert "rockjit.model" in graph["rockjit._engine.integrate"]


def test_no_import_cycle_in_the_package():
    cycles = _cycles(_graph())
    assert not cycles, [sorted(c) for c in cycles]


def _room(module):
    """``rockjit.grids.plan`` -> ``rockjit.grids``; ``rockjit.result`` stays itself."""
    parts = module.split(".")
    return ".".join(parts[:2])


def _rooms(graph):
    """The arrows between rooms, each with the module imports that draw it."""
    arrows = {}
    for m, deps in graph.items():
        for d in deps:
            if _room(m) != _room(d):
                arrows.setdefault(_room(m), {}).setdefault(_room(d), []).append(f"{m} -> {d}")
    return arrows


def test_the_room_reader_joins_a_subpackage():
    graph = {"rockjit.a.x": {"rockjit.b"}, "rockjit.a.y": {"rockjit.a.x"},
             "rockjit.b": {"rockjit.a.y"}}
    arrows = _rooms(graph)
    assert set(arrows) == {"rockjit.a", "rockjit.b"}
    assert _cycles({k: set(v) for k, v in arrows.items()}) == {frozenset({"rockjit.a",
                                                                          "rockjit.b"})}


def test_no_import_runs_back_up_the_house():
    # e.g. grids -> basins while basins -> grids, result -> basins while basins -> result,
    # study -> cli while cli -> study
    arrows = _rooms(_graph())
    cycles = sorted(_cycles({k: set(v) for k, v in arrows.items()}), key=lambda c: (len(c),
                                                                                    sorted(c)))
    shortest = [sorted(w for a in c for b, why in arrows[a].items() if b in c for w in why)
                for c in cycles[:3]]
    assert not cycles, f"{len(cycles)} loops between rooms; the shortest, by their imports: " \
                       f"{shortest}"


def test_only_the_entry_points_import_the_command_line():
    graph = _graph()
    users = {m for m, deps in graph.items() for d in deps
             if d.startswith("rockjit.cli") and not m.startswith("rockjit.cli")}
    assert users == set(), users  # (rockjit/__main__.py, the entry point, is no module here)


def test_the_package_holds_no_test_tools():
    assert not (PKG / "testing").exists()
    assert not [m for m in MODULES if "test" in m.rpartition(".")[2]]


def test_the_engine_imports_neither_storage_nor_scheduling():
    graph = _graph()
    engine = [m for m in graph if m.startswith("rockjit._engine")]
    assert engine
    for m in engine:
        outside = {d for d in graph[m] if not d.startswith("rockjit._engine")}
        assert outside <= {"rockjit._jit", "rockjit.model", "rockjit.laws.impact", "rockjit.plugs",
                           "rockjit.plugs.harmonic", "rockjit.result",
                           "rockjit.validate", "rockjit.excitation", "rockjit.settings"}, \
            (m, outside)


@pytest.mark.parametrize("path", sorted(PKG.rglob("*.py")) + sorted(ROOT.glob("benchmarks/*.py"))
                         + sorted(ROOT.glob("tests/**/*.py")), ids=lambda p: str(p.relative_to(ROOT)))
def test_every_file_opens_with_what_it_is_for(path):
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
    assert doc and len(doc.splitlines()[0].split()) >= 3, f"{path.name}: no opening line"
