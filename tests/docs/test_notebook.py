"""The notebooks run from top to bottom, show their figures, print what they promise, and are
stored with the outputs the code draws today.

Each notebook is stored executed (``python notebooks/execute.py``), so that a reader sees its
figures without running it. Here it is run again on this checkout's rockjit and compared with
what is stored, cell by cell: the same kinds of output in the same order (printed text, figures
as PNG), every figure present in both, and the same printed text (the runs are deterministic).
A notebook stored without outputs, or with outputs of older code, fails.
"""

import base64
import os
import sys
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = ROOT / "notebooks"


@pytest.fixture(autouse=True)
def _kernel_imports_this_checkout(monkeypatch):
    """The kernel runs in a temporary directory: put this checkout first on its path, so that
    the notebooks run the rockjit under test, not another installed copy."""
    path = os.environ.get("PYTHONPATH")
    monkeypatch.setenv("PYTHONPATH", str(ROOT) + (os.pathsep + path if path else ""))


def _run(name, tmp_path):
    nb = nbformat.read(NOTEBOOKS / name, as_version=4)
    NotebookClient(nb, timeout=900, kernel_name="python3",
                   resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    errors = [o for o in outputs if o.get("output_type") == "error"]
    assert not errors, errors[0].get("evalue")
    text = "\n".join(o.get("text", "") for o in outputs)
    return nb, outputs, text


def _figure_cells(nb):
    """For each code cell that builds a figure, whether it displays a PNG."""
    return [any("image/png" in o.get("data", {}) for o in c.get("outputs", []))
            for c in nb.cells if c.cell_type == "code" and "display(plotting." in c.source]


def _kinds(cell):
    """A code cell's outputs in kind: ``("stream", name)`` or ``("display_data", mime types)``,
    in order (consecutive writes to one stream count once: how a kernel splits them varies)."""
    out = []
    for o in cell.get("outputs", []):
        t = o["output_type"]
        k = (t, o.get("name")) if t == "stream" else (t, tuple(sorted(o.get("data", {}))))
        if not (out and out[-1] == k and t == "stream"):
            out.append(k)
    return out


def _stream_text(cell):
    return "".join(o.get("text", "") for o in cell.get("outputs", [])
                   if o["output_type"] == "stream")


def _png(o):
    data = base64.b64decode(o["data"]["image/png"])
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return data


def _stored_matches_a_fresh_run(name, fresh):
    stored = nbformat.read(NOTEBOOKS / name, as_version=4)
    code_s = [c for c in stored.cells if c.cell_type == "code"]
    code_f = [c for c in fresh.cells if c.cell_type == "code"]
    assert [c.source for c in code_s] == [c.source for c in code_f]
    assert any(c.get("outputs") for c in code_s), (
        f"{name} is stored without outputs: run python notebooks/execute.py")
    for i, (s, f) in enumerate(zip(code_s, code_f)):
        where = f"{name}, code cell {i}: {s.source.splitlines()[0] if s.source else ''!r}"
        assert _kinds(s) == _kinds(f), f"{where}: stored outputs are not what the code draws"
        assert _stream_text(s) == _stream_text(f), f"{where}: printed text differs"
        for o_s, o_f in zip((o for o in s.outputs if "image/png" in o.get("data", {})),
                            (o for o in f.outputs if "image/png" in o.get("data", {}))):
            assert len(_png(o_s)) > 1000 and len(_png(o_f)) > 1000, where
        if s.execution_count is not None:
            assert s.execution_count == f.execution_count, where


def test_tour_notebook_executes_and_shows_its_figures(tmp_path):
    nb, outputs, text = _run("tour.ipynb", tmp_path)
    shown = _figure_cells(nb)
    assert len(shown) >= 5 and all(shown)  # a reader sees every figure (Agg showed none)
    assert "behaviour: ('symmetric', 1)" in text
    # the printed exponent sum and the identity agree to the printed digits
    line = next(ln for ln in text.splitlines() if ln.startswith("sum:"))
    total, identity = (float(x) for x in line.replace("sum:", "").split("identity:"))
    assert total == pytest.approx(identity, rel=1e-8)
    # the attractor section finds two symmetric attractors, one of them through rest
    sym = [ln for ln in text.splitlines() if ln.startswith("attractor") and "symmetric" in ln]
    assert len(sym) >= 2 and any("multipliers [0. 0.]" in ln for ln in sym)
    assert "GIM = " in text and "GIM:" in text
    _stored_matches_a_fresh_run("tour.ipynb", nb)


def test_study_notebook_reproduces_the_study_from_python(tmp_path):
    nb, outputs, text = _run("study.ipynb", tmp_path)
    shown = _figure_cells(nb)
    assert len(shown) >= 6 and all(shown)
    # the restitution table of docs/theory/impacts.md, as printed
    assert "hb = 1: thc = 0.7854, e_H = 0.250, e_M = 0.582, delta e = 79.85 %" in text
    assert "hb = 2: thc = 1.1071, e_H = 0.700, e_M = 0.830, delta e = 17.03 %" in text
    assert "('symmetric', 1)" in text and "agreement" in text
    _stored_matches_a_fresh_run("study.ipynb", nb)


def test_the_comparison_catches_a_notebook_stored_without_outputs(tmp_path, monkeypatch):
    stored = nbformat.read(NOTEBOOKS / "tour.ipynb", as_version=4)
    fresh = nbformat.read(NOTEBOOKS / "tour.ipynb", as_version=4)
    for c in stored.cells:
        if c.cell_type == "code":
            c.outputs, c.execution_count = [], None
    nbformat.write(stored, tmp_path / "tour.ipynb")
    monkeypatch.setattr(sys.modules[__name__], "NOTEBOOKS", tmp_path)
    with pytest.raises(AssertionError, match="without outputs"):
        _stored_matches_a_fresh_run("tour.ipynb", fresh)
