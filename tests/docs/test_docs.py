"""The documentation's promises, checked: every example in a public docstring runs and prints
what it says; every public object is documented; the outputs page lists every file, array and
summary key each command writes; the performance page includes every benchmark's results; the
command-line reference covers every option.

The site itself is built by ``.ci/run`` (``python -m sphinx -W --keep-going -n``), which also
executes the guides and the gallery and validates the docstrings with numpydoc; these tests need
neither Sphinx nor a kernel.
"""

from __future__ import annotations

import doctest
import importlib
import importlib.util
import inspect
import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import rockjit

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"

#: The modules whose docstrings the site renders: their examples are the doctests.
PUBLIC_MODULES = [
    "rockjit.model", "rockjit.excitation", "rockjit.settings", "rockjit.single",
    "rockjit.result", "rockjit.grids.plan", "rockjit.grids.sweep_grid",
    "rockjit.grids.basin_grid", "rockjit.grids.plane_grid", "rockjit.basins.erosion",
    "rockjit.basins.fate", "rockjit.measures", "rockjit.storage.output_dir",
    "rockjit.orbits.shooting", "rockjit.orbits.arclength",
    "rockjit.orbits.types", "rockjit.grids.identity", "rockjit.grids.cycles",
    "rockjit.orbits.curves", "rockjit.orbits.curve_types", "rockjit.orbits.bifurcation_curve",
    "rockjit.orbits.plane_chart",
    "rockjit.ground.records", "rockjit.ground.fema", "rockjit.ground.settings",
    "rockjit.ground.response", "rockjit.ground.spectrum", "rockjit.ground.fitting",
    "rockjit.ground.fragility", "rockjit.reprs", "rockjit.laws", "rockjit.laws.base",
    "rockjit.laws.housner", "rockjit.laws.mao", "rockjit.laws.constant", "rockjit.laws.speed",
    "rockjit.plugs", "rockjit.plugs.base", "rockjit.plugs.harmonic_sum",
    "rockjit.plugs.pulse", "rockjit.plugs.record",
]
if importlib.util.find_spec("bokeh") is not None:  # the explorer's example starts its server
    PUBLIC_MODULES.append("rockjit.explorer")


# ------------------------------------------------------------------------------- doctests

def _doctests():
    finder = doctest.DocTestFinder(exclude_empty=True)
    found = {}
    for name in PUBLIC_MODULES:
        module = importlib.import_module(name)
        for test in finder.find(module):
            if test.examples and test.name not in found:
                found[test.name] = test
    return [found[k] for k in sorted(found)]


DOCTESTS = _doctests()


def test_there_are_doctests():
    assert len(DOCTESTS) >= 40, [t.name for t in DOCTESTS]


@pytest.mark.parametrize("test", DOCTESTS, ids=[t.name for t in DOCTESTS])
def test_docstring_example(test):
    """Each example runs and prints exactly what its docstring shows."""
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    out = []
    runner.run(test, out=out.append, clear_globs=True)
    assert runner.failures == 0, "".join(out)


# ------------------------------------------------------------------------------- public API

def _public_objects():
    """``(qualified name, object)`` of everything the API reference documents."""
    from rockjit import ground, orbits
    from rockjit import measures
    from rockjit.basins import erosion, fate
    from rockjit.single import Prepared
    from rockjit.storage import output_dir
    spectrum = sys.modules["rockjit.ground.spectrum"]  # (rockjit.ground.spectrum: the function)
    out = [(f"rockjit.{n}", getattr(rockjit, n)) for n in rockjit.__all__]
    out += [(f"rockjit.ground.{n}", getattr(ground, n)) for n in ground.__all__]
    out += [("rockjit.ground.spectrum.compare", spectrum.compare),
            ("rockjit.single.Prepared", Prepared),
            ("rockjit.orbits.ChartResult", orbits.ChartResult),
            ("rockjit.orbits.BifurcationCurve", orbits.BifurcationCurve)]
    out += [(f"rockjit.measures.{n}", getattr(measures, n)) for n in measures.__all__]
    from rockjit import laws, plugs
    out += [(f"rockjit.laws.{n}", getattr(laws, n)) for n in laws.__all__]
    out += [(f"rockjit.plugs.{n}", getattr(plugs, n)) for n in plugs.__all__]
    out += [("rockjit.basins.erosion.ErosionResult", erosion.ErosionResult),
            ("rockjit.basins.fate.FateResult", fate.FateResult),
            ("rockjit.storage.output_dir.OutputDir", output_dir.OutputDir)]
    return [(n, o) for n, o in out if inspect.isclass(o) or inspect.isfunction(o)
            or hasattr(o, "plan")]


PUBLIC = _public_objects()


@pytest.mark.parametrize("name, obj", PUBLIC, ids=[n for n, _ in PUBLIC])
def test_public_object_is_documented(name, obj):
    """A numpydoc docstring with its parameters (or a class's attributes) and an example."""
    doc = inspect.getdoc(obj) or ""
    assert re.search(r"^Examples\n-{8}", doc, re.M), f"{name}: no Examples section"
    sig_params = [p for p in inspect.signature(obj).parameters.values()
                  if p.name not in ("self",)]
    if sig_params:
        assert re.search(r"^(Parameters|Attributes)\n-{5,}", doc, re.M), \
            f"{name}: no Parameters (or Attributes) section"
    if inspect.isclass(obj):
        for attr, member in vars(obj).items():
            if attr.startswith("_"):
                continue
            func = member.fget if isinstance(member, property) else \
                getattr(member, "func", member)
            if inspect.isfunction(func):
                assert inspect.getdoc(func), f"{name}.{attr}: no docstring"


def test_the_reference_lists_every_public_name():
    text = "\n".join(p.read_text() for p in sorted((DOCS / "reference").glob("*.md")))
    listed = set(re.findall(r"^\s+([A-Za-z_][\w.]*)\s*$", text, re.M))
    listed |= set(re.findall(r"py:data:: (\w+)", text))
    missing = [n for n in rockjit.__all__ if n not in listed]
    assert not missing, f"add to a page of docs/reference/: {missing}"


# ------------------------------------------------------------------------------- outputs page

def _sections(text):
    """``{name: text}`` of the ``(outputs-<name>)=`` sections of the outputs page."""
    parts = re.split(r"^\(outputs-([\w-]+)\)=$", text, flags=re.M)
    return dict(zip(parts[1::2], parts[2::2]))


def _patterns(section):
    """The backquoted names of a section as regular expressions (``<law>`` and the like match
    any name part)."""
    out = []
    for token in re.findall(r"`([^`\n]+)`", section):
        rx = re.sub(r"<\w+>", "@@", token)
        rx = re.escape(rx).replace("@@", r"[A-Za-z0-9_.]+")
        out.append(re.compile(rx))
    return out


def _listed(name, patterns):
    return any(p.fullmatch(name) for p in patterns)


OUTPUTS = _sections((DOCS / "guide" / "outputs.md").read_text())
#: npz archives whose arrays another section lists ("with the arrays of `sweep.npz`")
SHARED_ARRAYS = {"sweep.npz": "sweep", "erosion.npz": "erosion", "orbits.npz": "orbits",
                 "chart.npz": "chart"}

#: stands for two small record files (two-column CSV, written by the test)
RECORDS = "<records>"
BASIN = ["--hb", "1", "--alpha", "0.66", "--omega", "1.3", "--grid", "6", "--periods", "20"]
TINY = ["--periods", "20", "--quiet"]

#: (test id, section, command line): a tiny run of every command, with the options that add
#: files or arrays
RUNS = [
    ("trajectory", "trajectory", ["trajectory", "--hb", "1", "--alpha", "0.6", "--omega", "1.3",
                                  "--lyapunov"] + TINY),
    ("sweep", "sweep", ["sweep", "--hb", "1", "--omega", "1.3", "--alpha-range", "0.5", "0.9",
                        "--alpha-step", "0.1", "--continue-past-overturn"] + TINY),
    ("sweep-uncertain", "sweep", ["sweep", "--hb", "1", "--omega", "1.3", "--alpha-range", "0.5",
                                  "0.7", "--alpha-step", "0.1", "--uncertainty", "1e-3"] + TINY),
    ("basin", "basin", ["basin", "--lyapunov", "--quiet"] + BASIN),
    ("basin-both", "basin", ["basin", "--law", "both", "--lyapunov", "--quiet"] + BASIN),
    ("basin-uncertain", "basin", ["basin", "--uncertainty", "1e-3", "--quiet"] + BASIN),
    ("plane", "plane", ["plane", "--hb", "1", "--alpha-range", "0.5", "0.7", "--omega-range",
                        "1.2", "1.4", "--grid", "3", "3"] + TINY),
    ("plane-uncertain", "plane", ["plane", "--hb", "1", "--alpha-range", "0.5", "0.7",
                                  "--omega-range", "1.2", "1.4", "--grid", "3", "3",
                                  "--uncertainty", "1e-3"] + TINY),
    ("erosion", "erosion", ["erosion", "--hb", "1", "--law", "both", "--omega", "1.3",
                            "--alpha-range", "0.6", "0.7", "--alpha-step", "0.05",
                            "--grid", "6"] + TINY),
    ("fate", "fate", ["fate", "--hb", "1", "--alpha", "0.969", "--omega", "1.3", "--ensemble",
                      "4"] + TINY),
    ("cor", "cor", ["cor", "--quiet"]),
    ("orbits", "orbits", ["orbits", "--hb", "1", "--omega", "1.3", "--alpha-range", "0.7",
                          "0.85", "--alpha-step", "0.01", "--periods", "100", "--quiet"]),
    ("paper", "paper", ["paper", "--grid", "4", "--periods", "20", "--n-steps", "64",
                        "--alpha-step", "0.1", "--zoom-step", "0.05", "--as-published",
                        "--quiet"]),
    ("chart", "chart", ["chart", "--hb", "1", "--alpha-range", "0.2", "1.2", "--omega-range",
                        "0.8", "3", "--grid", "8", "6", "--max-period", "1", "--seed-omegas",
                        "1.2"] + TINY),
    ("chart-both", "chart", ["chart", "--hb", "1", "--law", "both", "--alpha-range", "0.2",
                             "1.2", "--omega-range", "0.8", "3", "--grid", "8", "6",
                             "--max-period", "1", "--seed-omegas", "1.2"] + TINY),
    ("spectrum", "spectrum", ["spectrum", "--hb", "4", "--ratio-range", "1", "5",
                              "--amplitude-range", "1.5", "9", "--grid", "2", "2", "--tol",
                              "1e-3", "--quiet"]),
    ("spectrum-both", "spectrum", ["spectrum", "--hb", "4", "--law", "both", "--ratio-range",
                                   "1", "5", "--amplitude-range", "1.5", "9", "--grid", "2",
                                   "2", "--tol", "1e-3", "--quiet"]),
    ("fragility-both", "fragility", ["fragility", "--hb", "3", "--law", "both", "--size", "0.5",
                                     "2", "--records", RECORDS, "--intensities", "0.9", "4",
                                     "--free-time", "20", "--quiet"]),
]

def _marks(run_id):
    return []


def _records(directory):
    """Two short synthetic accelerograms (time in s, acceleration in g) as CSV files."""
    files = []
    for seed in (1, 2):
        rng = np.random.default_rng(seed)
        t = np.arange(401) * 0.01
        a = sum(rng.normal(0, 0.1) * np.sin(2 * np.pi * f * t + rng.uniform(0, 6))
                for f in (0.6, 1.4, 3.1)) * np.sin(np.pi * t / t[-1]) ** 2
        path = directory / f"record{seed}.csv"
        path.write_text("time (s),acceleration (g)\n" +
                        "".join(f"{x:.2f},{y:.8f}\n" for x, y in zip(t, a)))
        files.append(str(path))
    return files


@pytest.mark.parametrize("section, argv", [pytest.param(s, a, id=i, marks=_marks(i))
                                           for i, s, a in RUNS])
def test_outputs_page_lists_what_a_command_writes(section, argv, tmp_path):
    from rockjit.cli.main import main
    out = tmp_path / "out"
    if RECORDS in argv:
        i = argv.index(RECORDS)
        argv = argv[:i] + _records(tmp_path) + argv[i + 1:]
    assert main(argv + ["--out", str(out)]) == 0
    own = OUTPUTS[section]
    patterns = _patterns(own)
    common = _patterns(OUTPUTS["common"])
    written = sorted(p.name for p in out.iterdir())
    summary = json.loads((out / "summary.json").read_text())
    # the manifest: every file written, each with what it holds in words
    assert all(set(f) == {"name", "holds"} for f in summary["files"]), summary["files"]
    assert sorted(f["name"] for f in summary["files"]) == written
    undescribed = [f["name"] for f in summary["files"]
                   if not (isinstance(f["holds"], str) and f["holds"].strip())]
    assert not undescribed, f"summary.json's files: nothing said of {undescribed}"
    missing = [f for f in written if not _listed(f, patterns + common)]
    assert not missing, f"docs/guide/outputs.md, section {section}: add the files {missing}"
    for f in written:
        if not f.endswith(".npz"):
            continue
        arrays = list(patterns)
        for shared, other in SHARED_ARRAYS.items():
            if f"arrays of `{shared}`" in own:
                arrays += _patterns(OUTPUTS[other])
        with np.load(out / f) as z:
            keys = [k for k in z.files if not _listed(k, arrays)]
        assert not keys, f"docs/guide/outputs.md, section {section}: {f} holds {keys}"
    keys = [k for k in summary if not _listed(k, patterns + common)]
    assert not keys, f"docs/guide/outputs.md, section {section}: summary.json's keys {keys}"


def test_outputs_page_has_a_section_per_command():
    from rockjit.cli.main import build_parser
    sub = next(a for a in build_parser()._actions if hasattr(a, "choices") and a.choices)
    assert set(sub.choices) <= set(OUTPUTS), set(sub.choices) - set(OUTPUTS)


# ------------------------------------------------------------------------------- generated pages

def _ext(name):
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(DOCS / "_ext"))


def test_performance_page_includes_every_benchmark():
    page = (DOCS / "performance.md").read_text()
    results = sorted(p.stem for p in (ROOT / "benchmarks" / "results").glob("*.md"))
    # grids_section.md joins grids.md and paper.md for benchmarks/README.md
    missing = [r for r in results if r != "grids_section"
               and f"_generated/bench/{r}.md" not in page]
    assert not missing, f"include in docs/performance.md: {missing}"
    for script in re.findall(r"python benchmarks/(\S+\.py)", page):
        assert (ROOT / "benchmarks" / script).exists(), script


def test_command_line_reference_lists_every_command_and_option():
    import argparse
    from rockjit.cli.main import build_parser
    text = _ext("rockjit_cli").render()
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, p in sub.choices.items():
        assert f"(cli-{name})=" in text and f"## `rockjit {name}`" in text, name
        section = text.split(f"(cli-{name})=", 1)[1].split("(cli-", 1)[0]
        for action in p._actions:
            for opt in action.option_strings:
                if opt not in ("-h", "--help"):
                    assert f"`{opt}" in section or f", {opt}" in section, (name, opt)


def test_no_internal_references_in_what_the_site_renders():
    """The command-line reference and the package's docstrings say what the code does: no work
    item, specification or style-guide number (the benchmark results alone are cleaned when
    the site is built, below). The compiled engine's modules are not rendered on the site."""
    sc = _ext("_scrub")
    internal = re.compile(rf"{sc._ITEM}|{sc._SPEC}|STYLE\.md")
    cli = _ext("rockjit_cli").render()
    assert not internal.search(cli), internal.search(cli).group(0)
    found = []
    for path in sorted((ROOT / "rockjit").rglob("*.py")):
        if "_engine" in path.relative_to(ROOT).parts:
            continue
        for n, line in enumerate(path.read_text().splitlines(), 1):
            if internal.search(line):
                found.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    assert not found, "\n".join(found)


def test_scrub_keeps_the_figures():
    """The results as the site shows them: no internal reference left, every table row that
    had none unchanged."""
    sc = _ext("_scrub")
    internal = re.compile(rf"{sc._ITEM}|{sc._SPEC}|\b{sc._RUN}")
    for md in sorted((ROOT / "benchmarks" / "results").glob("*.md")):
        text = md.read_text()
        shown = sc.scrub(text)
        assert not internal.search(shown), md.name
        rows = [r for r in text.splitlines() if r.startswith("|") and not internal.search(r)]
        assert set(rows) <= set(shown.splitlines()), md.name


def test_no_control_characters_in_the_texts():
    # a backslash sequence written through a string that interprets it ("\a" in "\approx")
    # leaves a control character the page shows as nothing
    bad = []
    for folder in ("docs", "rockjit", "benchmarks", "tests", "notebooks"):
        for path in (ROOT / folder).rglob("*"):
            if "_build" in path.parts or path.suffix not in (".md", ".py", ".rst", ".ipynb"):
                continue
            text = path.read_text(encoding="utf-8")
            bad += [f"{path.relative_to(ROOT)}: {hex(ord(c))}" for c in set(text)
                    if ord(c) < 32 and c not in "\n\t\r"]
    assert not bad, bad


# ------------------------------------------------------------------------------- offline site

def _ext(name):
    pytest.importorskip("sphinx")
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(DOCS / "_ext"))


def test_the_formulas_render_from_the_site_itself(tmp_path):
    """MathJax is installed with the docs extra and served with the site: the pages load it
    from ``_static``, and the files it loads on demand (fonts, TeX extensions) are there too."""
    mj = _ext("rockjit_mathjax")
    extra = (ROOT / "pyproject.toml").read_text()
    assert re.search(r'^docs = \[[^\]]*"django-static-mathjax', extra, re.M | re.S)
    assert not mj.MATHJAX_PATH.startswith(("http:", "https:", "//"))
    es5 = mj.source()
    if es5 is None:
        pytest.skip("the docs extra is not installed here")
    names = mj.collect(es5, tmp_path)
    assert mj.MATHJAX_PATH == "mathjax/tex-chtml.js" and "tex-chtml.js" in names
    assert (tmp_path / mj.MATHJAX_PATH).read_bytes() == (es5 / "tex-chtml.js").read_bytes()
    fonts = [n for n in names if n.startswith("output/chtml/fonts/woff-v2/")]
    assert any("MathJax_Main-Regular" in n for n in fonts), fonts[:5]
    assert any(n.startswith("input/tex/extensions/") for n in names)
    # nothing copied again where nothing changed
    before = {p: p.stat().st_mtime_ns for p in tmp_path.rglob("*") if p.is_file()}
    mj.collect(es5, tmp_path)
    assert {p: p.stat().st_mtime_ns for p in tmp_path.rglob("*") if p.is_file()} == before


def test_conf_points_mathjax_and_the_kernels_at_local_settings():
    conf = (DOCS / "conf.py").read_text()
    assert "rockjit_mathjax" in conf and "cdn" not in conf.lower()
    # the executed pages' kernels log errors only (each warned about its local TCP link)
    assert "c.IPKernelApp.log_level = 'ERROR'" in conf and 'os.environ["IPYTHONDIR"]' in conf
    css = (DOCS / "_css" / "rockjit.css").read_text()
    assert re.search(r"div\.highlight pre,[^{]*\{[^}]*white-space: pre-wrap", css, re.S)


def _toctree(text):
    return re.search(r"```\{toctree\}\n(?::[^\n]*\n)*\n(.*?)```", text, re.S).group(1).split()


def test_the_reference_is_grouped_as_the_guide_is():
    pages = _toctree((DOCS / "reference" / "index.md").read_text())
    assert len(pages) >= 6
    listed = {}
    for page in pages:
        text = (DOCS / "reference" / f"{page}.md").read_text()
        assert text.startswith(("# ", "(api-orbits)=\n# ")), page
        listed[page] = set(re.findall(r"^\s+([A-Za-z_]\w*)\s*$", text, re.M))
    assert {"simulate", "sweep", "basin", "fate", "spectrum"} <= listed["entry-points"]
    assert max(len(v) for v in listed.values()) < 25  # no page is one flat list of everything


def test_the_gallery_index_shows_a_thumbnail_per_page():
    index = (DOCS / "gallery" / "index.md").read_text()
    grid = re.search(r"```\{rockjit-gallery\}\n(.*?)```", index, re.S).group(1).split()
    assert grid == _toctree(index)
    assert _ext("rockjit_gallery").ENV_KEY


# ------------------------------------------------------------------------------- one symbol

def test_alpha_is_the_forcing_amplitude_only_in_what_a_user_reads():
    """The uplift threshold is written ``g cot theta_c`` (= g b/h) and the tipping angle
    ``pi/2 - theta_c``: the command line's help, a pulse's line, the fragility measure's name,
    the ground figures' labels and the pages on ground motions never call them alpha."""
    from rockjit import Pulse
    from rockjit.cli.main import build_parser
    from rockjit.ground import figures as GF
    from rockjit.ground.fragility import MEASURES
    parser = build_parser()
    sub = next(a for a in parser._actions if hasattr(a, "choices") and a.choices)
    for command in ("spectrum", "fragility"):
        helps = " ".join(str(a.help) for a in sub.choices[command]._actions)
        assert "cot theta_c" in helps and "tan alpha" not in helps, command
    line = Pulse("sine", ratio=2.0, amplitude=3.0).describe()
    assert "a_p/(g cot theta_c) = 3" in line and "alpha" not in line
    assert MEASURES["pga"] == "PGA / (g cot theta_c)"
    assert GF.AMPLITUDE == r"$a_p / (g \cot\theta_c)$"
    source = Path(GF.__file__).read_text()
    assert r"\tan\theta_c" not in source and r"/ \theta_c" not in source
    for page in ("guide/earthquakes.md", "theory/ground-motions.md"):
        text = (DOCS / page).read_text()
        assert r"\tan\alpha_s" not in text, page
