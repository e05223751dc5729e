"""Sphinx extension: the reference list of :mod:`rockjit.orbits`, generated at build time.

``rockjit.orbits`` is being redesigned; rather than a hand-kept list that would go stale, this
writes ``docs/_generated/orbits-api.md`` from its public names when the site is built: the
package's ``__all__`` when it has one, else its ``orbits`` module's. Classes and functions go
into an autosummary table (with generated pages), constants into ``autodata`` entries.
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path

from rockjit_cli import GENERATED, write_if_changed


def public_names(package="rockjit.orbits"):
    """``(module, names)``: where the public names of ``package`` are documented from."""
    pkg = importlib.import_module(package)
    if getattr(pkg, "__all__", None):
        return package, list(pkg.__all__)
    mod = importlib.import_module(package + ".orbits")
    return mod.__name__, list(mod.__all__)


def render(package="rockjit.orbits"):
    module, names = public_names(package)
    mod = importlib.import_module(module)
    objects = [n for n in names if inspect.isclass(getattr(mod, n)) or callable(getattr(mod, n))]
    data = [n for n in names if n not in objects]
    lines = [f"<!-- generated from {module}'s public names by docs/_ext/rockjit_api.py -->", "",
             "```{eval-rst}", f".. currentmodule:: {module}", "",
             ".. autosummary::", "   :toctree: ../reference/generated", ""]
    lines += ["   " + n for n in objects] + ["```", ""]
    if data:
        lines += ["```{eval-rst}"] + [f".. autodata:: {module}.{n}" for n in data] + ["```"]
    return "\n".join(lines) + "\n"


def _generate(app, config=None):
    write_if_changed(Path(app.srcdir) / GENERATED / "orbits-api.md", render())


def setup(app):
    app.connect("config-inited", _generate)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
