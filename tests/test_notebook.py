"""The tour notebook runs from top to bottom and shows what it promises."""

from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOK = Path(__file__).resolve().parents[1] / "notebooks" / "tour.ipynb"


def test_tour_notebook_executes(tmp_path):
    nb = nbformat.read(NOTEBOOK, as_version=4)
    NotebookClient(nb, timeout=600, kernel_name="python3",
                   resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = "\n".join(o.get("text", "") for c in nb.cells if c.cell_type == "code"
                        for o in c.get("outputs", []))
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if o.get("output_type") == "error"]
    assert not errors
    assert "behaviour: ('symmetric', 1)" in outputs
    # the printed exponent sum and the identity agree to the printed digits
    line = next(l for l in outputs.splitlines() if l.startswith("sum:"))
    total, identity = (float(x) for x in line.replace("sum:", "").split("identity:"))
    assert total == pytest.approx(identity, rel=1e-8)
