"""Sphinx extension: the benchmark results, as the scripts last wrote them, on the site.

At ``builder-inited`` every ``benchmarks/results/<name>.md`` is copied to
``docs/_generated/bench/<name>.md`` (git-ignored) and every plot beside it, so that
``docs/performance.md`` can ``{include}`` the current figures: rerunning a script and rebuilding
the site updates the page. On the way, the headings are renumbered to start at level
:data:`BASE` with no level skipped (the page's own section is level 2), and the notes are
cleaned (:func:`_scrub.scrub`).
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

from _scrub import scrub
from rockjit_cli import GENERATED, write_if_changed

BASE = 3
_HEADING = re.compile(r"^(#{1,6})(\s+.*)$", re.MULTILINE)


def renumber(text, base=BASE):
    """Headings mapped level by level (in sorted order) onto ``base, base + 1, ...``."""
    levels = sorted({len(m.group(1)) for m in _HEADING.finditer(text)})
    new = {lvl: min(base + i, 6) for i, lvl in enumerate(levels)}
    return _HEADING.sub(lambda m: "#" * new[len(m.group(1))] + m.group(2), text)


def convert(text):
    """A results file as the site shows it."""
    return renumber(scrub(text)).rstrip() + "\n"


def _generate(app, config=None):
    results = Path(app.srcdir).parent / "benchmarks" / "results"
    out = Path(app.srcdir) / GENERATED / "bench"
    out.mkdir(parents=True, exist_ok=True)
    for md in sorted(results.glob("*.md")):
        write_if_changed(out / md.name, convert(md.read_text()))
    for png in sorted(results.glob("*.png")):
        target = out / png.name
        if not target.exists() or target.read_bytes() != png.read_bytes():
            shutil.copyfile(png, target)


def setup(app):
    app.connect("config-inited", _generate)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
