"""Sphinx extension: the site's formulas rendered by a local MathJax, so that they show offline.

MathJax 3 comes from the ``django-static-mathjax`` package (``pip install -e ".[docs]"``
installs it; its Python module is ``mathjax``, its files are MathJax's own). At
``config-inited`` the part the site needs (:data:`PARTS`: the TeX-to-HTML component, its
fonts, the TeX extensions it loads on demand, the menu and accessibility components, about
5 MB of the package's 24) is copied to ``docs/_generated/static/mathjax/`` (git-ignored, only
what changed), that folder is added to ``html_static_path`` and ``mathjax_path`` points at it:
the built site holds ``_static/mathjax/tex-chtml.js`` and asks no network for anything. Without
the package the build warns (an error with ``-W``) rather than fall back to a CDN.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from sphinx.util import logging

from rockjit_cli import GENERATED

#: MathJax's files the site serves, relative to the package's ``es5`` folder.
PARTS = ("tex-chtml.js", "output/chtml", "input/tex/extensions", "ui", "a11y", "adaptors")
#: Where the built site's pages load MathJax from (relative to ``_static``).
MATHJAX_PATH = "mathjax/tex-chtml.js"

logger = logging.getLogger(__name__)


def source():
    """MathJax's ``es5`` folder in the installed package, or None."""
    try:
        import mathjax
    except ImportError:
        return None
    es5 = Path(mathjax.__file__).parent / "static" / "mathjax" / "es5"
    return es5 if (es5 / "tex-chtml.js").is_file() else None


def _files(es5):
    for part in PARTS:
        p = es5 / part
        if p.is_file():
            yield p
        else:
            yield from (f for f in sorted(p.rglob("*")) if f.is_file())


def collect(es5, target):
    """Copy MathJax's :data:`PARTS` from ``es5`` into ``target/mathjax`` (files that differ
    only); returns the relative paths copied or already there."""
    names = []
    for f in _files(es5):
        rel = f.relative_to(es5)
        dst = target / "mathjax" / rel
        if not dst.is_file() or dst.stat().st_size != f.stat().st_size or \
                dst.read_bytes() != f.read_bytes():
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(f, dst)
        names.append(rel.as_posix())
    return names


def _setup_mathjax(app, config):
    es5 = source()
    if es5 is None:
        logger.warning("MathJax is not installed here: the formulas will not render "
                       "(pip install -e \".[docs]\" installs it)")
        return
    target = Path(app.srcdir) / GENERATED / "static"
    collect(es5, target)
    config.html_static_path = list(config.html_static_path) + [str(target)]
    config.mathjax_path = MATHJAX_PATH


def setup(app):
    app.connect("config-inited", _setup_mathjax)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
