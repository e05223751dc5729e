"""Run the notebooks from top to bottom and store them with their outputs (figures embedded),
so that a reader sees every result on GitHub or in Jupyter without running anything.

    python notebooks/execute.py              # both notebooks
    python notebooks/execute.py tour.ipynb   # one

``tests/docs/test_notebook.py`` runs them again and checks that what is stored is what the code now
draws and prints.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
NOTEBOOKS = ("tour.ipynb", "study.ipynb")


def execute(name, workdir=None):
    """The notebook ``name`` executed on this checkout's rockjit (returned, not written)."""
    import nbformat
    from nbclient import NotebookClient
    nb = nbformat.read(HERE / name, as_version=4)
    path = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = str(ROOT) + (os.pathsep + path if path else "")
    try:
        with tempfile.TemporaryDirectory() as tmp:
            NotebookClient(nb, timeout=900, kernel_name="python3",
                           resources={"metadata": {"path": str(workdir or tmp)}}).execute()
    finally:
        if path is None:
            os.environ.pop("PYTHONPATH", None)
        else:
            os.environ["PYTHONPATH"] = path
    return nb


def main(names):
    import nbformat
    for name in names or NOTEBOOKS:
        nb = execute(name)
        nbformat.write(nb, HERE / name)
        print(f"{name}: executed and stored with its outputs")


if __name__ == "__main__":
    main(sys.argv[1:])
