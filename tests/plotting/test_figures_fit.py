"""Every figure ``rockjit paper`` and each command draws keeps its text on the canvas and reads in
a journal, in both styles; every figure has its data file; every file is described.

The figures are caught as they are written (an output directory that keeps them instead of
saving them) and each visible text artist's drawn extent is compared with the figure's
(:func:`rockjit.plotting.legibility.texts_outside`): a clipped legend entry ("verturn"), a title
cut at the right edge or a label below the canvas fails here, naming the figure and the text.
"""

import re

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import rockjit  # noqa: E402
from rockjit import Block, Harmonic, Integration  # noqa: E402
from rockjit import outputs  # noqa: E402
from rockjit.plotting import legibility, style  # noqa: E402
from rockjit.study import paper as study  # noqa: E402

STYLES = ("default", "paper")


class CaughtOut:
    """An output directory that keeps what it is given: figures checked for text outside the
    canvas as they arrive (in the style in force), the other files by name."""

    def __init__(self):
        self.written, self.holds, self.outside, self.figures = [], {}, {}, []
        self.problems = {}

    def _add(self, name):
        if name not in self.written:
            self.written.append(name)

    def figure(self, name, fig, *, dpi=None):
        self.outside[name] = legibility.texts_outside(fig)
        self.problems[name] = legibility.problems(fig)
        self.figures.append(name)
        self._add(name)
        return name

    def npz(self, name, **arrays):
        assert arrays, name
        self._add(name)

    def json(self, name, obj):
        self._add(name)

    def text(self, name, text):
        assert text.strip(), name
        self._add(name)

    def table(self, stem, header, rows, fmt=None):
        self._add(stem + ".csv")
        self._add(stem + ".md")

    def describe(self, name, holds):
        self.holds[name] = holds


def _assert_fits(out):
    bad = {k: v for k, v in out.outside.items() if v}
    assert not bad, f"text outside the canvas: {bad}"


QUICK = dict(grid=8, periods=60, alpha_step=0.02, zoom_step=0.01, erosion_step=0.1,
             erosion_grid=8, as_published=True)


@pytest.fixture(scope="module", params=STYLES)
def paper_out(request):
    out = CaughtOut()
    with style.use(request.param):
        results = study.paper(out, study.plan_paper(**QUICK))
    return out, results


@pytest.mark.slow
def test_every_paper_figure_keeps_its_text_on_the_canvas(paper_out):
    out, _ = paper_out
    assert len(out.figures) == 22  # figures 1-9, the as-published pair and the branches
    _assert_fits(out)


@pytest.mark.slow
def test_every_paper_figure_reads_in_a_journal(paper_out):
    """A column or page wide, 7-9 pt type, legends that name what is drawn and tell their
    entries apart, no overprinted labels, no legend over the data
    (rockjit.plotting.legibility)."""
    out, _ = paper_out
    bad = {k: v for k, v in out.problems.items() if v}
    assert not bad, bad


@pytest.mark.slow
def test_every_paper_figure_has_its_data_and_every_file_is_described(paper_out):
    out, results = paper_out
    for fig in out.figures:
        assert fig in out.holds and "data:" in out.holds[fig], fig
        # the data files a figure names were written
        names = re.findall(r"[\w*]+\.(?:npz|md)", out.holds[fig].split("data:")[1])
        assert names, fig
        for n in names:
            if "*" not in n:
                assert n in out.written, (fig, n)
    assert set(out.written) <= set(out.holds), set(out.written) - set(out.holds)
    assert "index.html" in out.written


def _small_results():
    """One small result of each command."""
    run = rockjit.simulate(Block(hb=1.0), Harmonic(alpha=0.6, omega=1.3), lyapunov=True,
                           integration=Integration(periods=30), record_stride=2)
    integ = Integration(periods=60)
    sw = rockjit.sweep(Block(hb=1.0), Harmonic(omega=1.3), rockjit.alpha_grid((0.5, 1.0), 0.05),
                       integration=integ)
    basins = {law: rockjit.basin(Block(hb=1.0, law=law), Harmonic(alpha=0.66, omega=1.3), 8,
                                 integration=integ) for law in ("housner", "mao")}
    pl = rockjit.plane(Block(hb=1.0), (0.5, 0.9), (1.2, 1.4), grid=(3, 3), integration=integ)
    ero = {law: rockjit.erosion(Block(hb=1.0, law=law), Harmonic(omega=1.3),
                                rockjit.alpha_grid((0.5, 0.8), 0.1), 8, integration=integ)
           for law in ("housner", "mao")}
    fr = rockjit.fate(Block(hb=1.0), Harmonic(alpha=0.969, omega=1.3),
                      integration=Integration(periods=60), ensemble=8)
    from rockjit.orbits import ContinuationSettings, continue_branches
    cont = continue_branches(Block(hb=1.0), Harmonic(omega=1.3), (0.75, 0.82), sweep_step=0.01,
                             settings=ContinuationSettings(switch=True, max_period=2))
    osw = rockjit.sweep(Block(hb=1.0), Harmonic(omega=1.3),
                        rockjit.alpha_grid((0.75, 0.82), 0.01), integration=integ)
    return dict(run=run, sweep=sw, basins=basins, plane=pl, erosion=ero, fate=fr,
                orbits=(cont, osw))


@pytest.fixture(scope="module")
def small():
    return _small_results()


@pytest.mark.parametrize("name", STYLES)
def test_every_command_figure_keeps_its_text_on_the_canvas(small, name):
    out = CaughtOut()
    with style.use(name):
        outputs.trajectory(out, small["run"])
        outputs.sweep(out, small["sweep"])
        outputs.basins(out, small["basins"], npz="b2.npz", png="b2.png",
                       attractors_png="a2.png")
        outputs.basins(out, small["basins"]["mao"], npz="b1.npz", png="b1.png",
                       attractors_png="a1.png")
        outputs.plane(out, small["plane"])
        outputs.erosion(out, small["erosion"])
        outputs.fate(out, small["fate"])
        outputs.orbits(out, small["orbits"])
        study.write_e_table(out, study.E_TABLE_HB, study.E_FIGURE_HB_MAX, "restitution.png",
                            "e_table")
    assert len(out.figures) == 11
    _assert_fits(out)
    assert set(out.written) <= set(out.holds), set(out.written) - set(out.holds)


def test_the_check_catches_text_off_the_canvas():
    from matplotlib.figure import Figure
    fig = Figure(figsize=(3, 2))
    fig.subplots_adjust(left=0.2, bottom=0.25)
    ax = fig.add_subplot()
    ax.legend(handles=[matplotlib.lines.Line2D([], [], label="overturn")],
              loc="center left", bbox_to_anchor=(0.95, 0.5))
    bad = legibility.texts_outside(fig)
    assert [t for t, _ in bad] == ["overturn"]
    fig = Figure(figsize=(3, 2), layout="constrained")
    ax = fig.add_subplot()
    ax.set_title("a title that fits")
    assert legibility.texts_outside(fig) == []


def test_formats_and_paper_sizes(tmp_path):
    """``--format`` writes each figure in its format; the paper style's figures are a journal
    column wide."""
    from rockjit.storage.output_dir import OutputDir
    out = OutputDir(tmp_path / "o")
    out.figure_format = "svg"
    with style.use("paper"):
        name = out.figure("fig1_restitution.png", rockjit.plotting.figures.fig_restitution())
        fig = rockjit.plotting.figures.fig_restitution()
        assert fig.get_figwidth() == pytest.approx(3.5) and fig.get_suptitle() == ""
    assert name == "fig1_restitution.svg"
    out.publish()
    assert (tmp_path / "o" / "fig1_restitution.svg").read_text().lstrip().startswith("<?xml")
    with style.use("default"):
        assert rockjit.plotting.figures.fig_restitution().get_suptitle()
    np.testing.assert_equal(style.current().name, "default")
