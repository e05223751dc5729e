"""Every figure rockjit draws reads in a journal: a column or page wide with 7-9 pt type, legends
that name only what is drawn and tell their entries apart by more than a shade, no labels
printed over each other, no legend over the data (rockjit.plotting.legibility).

Each figure function is drawn from small inputs: short runs, small grids, and synthetic
results where a computed one would be slow (a continuation with branches of seven periods, an
erosion profile with twenty attractors, two laws' charts, spectra and fragility fits). The
checks themselves are tested on figures made to fail each one.
"""

from types import SimpleNamespace

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from matplotlib.figure import Figure  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

import rockjit  # noqa: E402
from rockjit import Block, Harmonic, Integration, Pulse, Transient  # noqa: E402
from rockjit.plotting import figures as P  # noqa: E402
from rockjit.plotting import legibility as L  # noqa: E402
from rockjit.plotting import style  # noqa: E402
from rockjit.result import BEHAVIOURS  # noqa: E402

RUN = dict(integration=Integration(periods=20, n_steps=64), record_stride=4, lyapunov=True)


# ---------------------------------------------------------------------------------------------
# the checks fail where they should
# ---------------------------------------------------------------------------------------------

def _fig(w=3.5, h=2.5):
    return Figure(figsize=(w, h), layout="constrained")


def test_canvas_width_is_a_column_or_a_page():
    assert L.canvas_problems(_fig(3.5)) == [] and L.canvas_problems(_fig(7.2)) == []
    assert L.canvas_problems(_fig(17.0, 6.2)) and L.canvas_problems(_fig(9.0))


def test_type_size():
    fig = _fig()
    ax = fig.add_subplot()
    ax.tick_params(labelsize=8)
    ax.set_xlabel("seven", fontsize=7)
    assert L.type_problems(fig) == []
    ax.set_title("too small", fontsize=5.6)
    assert [p for p in L.type_problems(fig) if "too small" in p]
    fig = _fig()
    fig.add_subplot().set_xlabel("too large", fontsize=11)
    assert L.type_problems(fig)


def test_overprinted_labels():
    fig = _fig()
    ax = fig.add_subplot()
    ax.tick_params(labelsize=7)
    ax.text(0.5, 0.5, "PD1", fontsize=8)
    ax.text(0.52, 0.5, "PD2", fontsize=8)
    bad = L.text_overlaps(fig)
    assert bad == ["'PD1' overprints 'PD2'"]
    ax.texts[1].set_position((0.5, 0.1))
    assert L.text_overlaps(fig) == []


def test_legend_entries_must_name_something_drawn():
    fig = _fig()
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], color="#228833", label="drawn")
    ax.plot([], [], color="#EE6677", label="no data")               # an invisible handle
    ax.plot([np.nan], [np.nan], color="#332288", label="all nan")   # nothing to see
    ax.plot([5, 6], [5, 6], color="#AA4499", label="outside")       # outside the view
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.legend(handles=ax.get_lines() + [Patch(color="#f2f2f2", label="near white")],
              loc="upper center", bbox_to_anchor=(0.5, -0.2))
    bad = L.legend_handle_problems(fig)
    assert bad == ["legend entry 'no data' names nothing drawn",
                   "legend entry 'all nan' names nothing drawn",
                   "legend entry 'outside' names nothing drawn",
                   "legend entry 'near white' is not seen on the legend's background"]
    # a black entry (a law's line, style.LAW_LINES) names nothing when only the axes' black
    # frame is drawn in black
    fig = _fig()
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], color="#228833", label="drawn")
    ax.plot([], [], label="law", lw=0.8, **dict(style.LAW_LINES["mao"], marker=None))
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), handlelength=4.0)
    assert L.legend_handle_problems(fig) == ["legend entry 'law' names nothing drawn"]
    ax.get_lines()[1].set_data([0, 1], [1, 0])
    assert L.legend_handle_problems(fig) == []


def test_a_dashed_entry_shows_its_dashes():
    fig = _fig()
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], color="k", ls=(0, (7, 3)), lw=1.8, label="symmetry breaking")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), handlelength=2.0)
    assert any("dash pattern" in p for p in L.legend_handle_problems(fig))
    ax.get_lines()[0].set_linewidth(0.8)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), handlelength=4.0)
    assert L.legend_handle_problems(fig) == []


def test_entries_told_apart_by_a_shade_only():
    green = style.BEHAVIOUR_COLOURS["multiperiodic"]
    fig = _fig()
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], color=green, label="period 2")
    ax.plot([0, 1], [1, 0], color=style.tint(green, 0.2), label="period 6")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2))
    bad = L.legend_colour_problems(fig)
    assert len(bad) == 1 and "'period 2' and 'period 6'" in bad[0]
    # the same two shades with a marker on one are told apart
    ax.get_lines()[1].set_marker("^")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2))
    assert L.legend_colour_problems(fig) == []
    # the distance is CAM02-UCS's: black and white are 100 apart, a colour and itself 0
    assert L.colour_distance("k", "w") == pytest.approx(100.0, abs=1.0)
    assert L.colour_distance(green, green) == 0.0


def test_legend_over_the_data():
    fig = _fig()
    ax = fig.add_subplot()
    ax.plot(np.linspace(0, 1, 50), np.linspace(0, 1, 50), color="k", label="diagonal")
    ax.legend(loc="center")
    assert L.legend_over_data(fig)
    ax.legend(loc="upper left")  # the diagonal leaves the upper left corner empty
    assert L.legend_over_data(fig) == []
    fig = _fig()
    ax = fig.add_subplot()
    ax.imshow(np.eye(4))
    ax.legend(handles=[Patch(color="k", label="one")], loc="upper right")
    assert L.legend_over_data(fig)


# ---------------------------------------------------------------------------------------------
# small inputs of every figure
# ---------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def runs():
    sym = rockjit.simulate(Block(hb=1.0), Harmonic(alpha=0.6, omega=1.3), **RUN)
    rest = rockjit.simulate(Block(hb=1.0), Harmonic(alpha=0.15, omega=1.0), (0.7, 0.0),
                            **dict(RUN, record_stride=1))
    over = rockjit.simulate(Block(hb=2.0), Harmonic(alpha=0.448, omega=1.3), **RUN)
    mao = rockjit.simulate(Block(hb=1.0, law="mao"), Harmonic(alpha=0.6, omega=1.3), **RUN)
    pulse = rockjit.simulate(Block(hb=4.0), Pulse("ricker", ratio=2.0, amplitude=2.0),
                             integration=Transient(free_time=5.0))
    return dict(sym=sym, rest=rest, over=over, mao=mao, pulse=pulse)


@pytest.fixture(scope="module")
def grids():
    integ = Integration(periods=40, n_steps=32)
    sw = {law: rockjit.sweep(Block(hb=1.0, law=law), Harmonic(omega=1.3),
                             rockjit.alpha_grid((0.5, 1.0), 0.05), integration=integ,
                             lyapunov=True) for law in ("housner", "mao")}
    bs = {law: rockjit.basin(Block(hb=1.0, law=law), Harmonic(alpha=0.66, omega=1.3), 8,
                             integration=integ) for law in ("housner", "mao")}
    pl = rockjit.plane(Block(hb=1.0), (0.5, 0.9), (1.2, 1.4), grid=(3, 3), integration=integ)
    pl2 = rockjit.plane(Block(hb=1.0), (0.5, 0.9), (1.2, 1.4), grid=(3, 3),
                        state=[(0.0, 0.0), (0.1, 0.0)], integration=integ)
    fr = rockjit.fate(Block(hb=1.0), Harmonic(alpha=0.969, omega=1.3),
                      integration=Integration(periods=60), ensemble=8)
    return dict(sweeps=sw, basins=bs, plane=pl, plane2=pl2, fate=fr)


def _branch(period, symmetric, value, y0, slope, ends=("range", "range"), stable=None):
    n = value.size
    cyc = np.empty((n, period, 2))
    for k in range(period):
        cyc[:, k, 0] = 0.1 * k
        cyc[:, k, 1] = y0 + 0.05 * k + slope * (value - value[0])
    st = np.ones(n, bool) if stable is None else stable
    mu = np.where(st[:, None], 0.5, 1.5) * np.ones((n, 2))
    return SimpleNamespace(period=period, symmetric=symmetric, value=value, alpha=value,
                           omega=np.full(n, 1.3), cycle=cyc, mirror_cycle=None,
                           t_next_impact=np.full((n, period), 0.1),
                           t_next_impact_half=np.full((n, period), 0.1), multipliers=mu,
                           stable=st, ends=ends)


def _continuation():
    """Branches of periods 1, 2, 3, 4, 6, 7 and 8; four branches that stop at one point for
    want of convergence; a grazing outside the zoom."""
    v = np.linspace(0.9, 1.0, 30)
    half = np.linspace(0.95, 1.0, 15)
    brs = [_branch(1, True, np.linspace(0.6, 0.85, 40), -0.3, -0.2,
                   ends=("range", "grazing")),
           _branch(1, False, v, -0.4, -0.3, stable=v < 0.95),
           _branch(2, False, half, -0.5, -0.2)]
    brs += [_branch(p, False, half, -0.6 - 0.1 * p, 0.3, ends=("no_convergence", "range"))
            for p in (3, 4, 6, 7, 8)]
    brs += [_branch(8, False, half, -0.6 - 0.8, 0.3, ends=("no_convergence", "range"))]
    bifs = [SimpleNamespace(type="symmetry_breaking", value=0.7, cycle=np.array([[0.0, -0.32]]),
                            has_mirror=False, cycle_half=None, period=1),
            SimpleNamespace(type="period_doubling", value=0.95,
                            cycle=np.array([[0.0, -0.415]]), has_mirror=False,
                            cycle_half=None, period=1)]
    return SimpleNamespace(parameter="alpha", branches=brs, bifurcations=bifs,
                           bounds=(0.6, 1.0), block=Block(hb=1.0),
                           forcing=Harmonic(omega=1.3), phase=-0.89)


def _erosion():
    """A profile with twenty attractors, most of them aperiodic and small, as the study's
    h/b = 1 Housner profile has, and orbits of periods 2, 3, 7 and 8."""
    alpha = np.round(np.arange(0.3, 1.0, 0.05), 2)
    na = alpha.size
    brs, fr = [], []

    def add(beh, period, share, rest=False):
        brs.append(dict(behaviour=beh, period=period,
                        multipliers=[[0.0, 0.0]] if rest else [[0.3, 0.1]]))
        fr.append(share)

    ramp = np.clip(np.linspace(-1, 2, na), 0, 1)
    add("rest", 0, 40 * (1 - ramp))
    add("symmetric", 1, 30 * ramp)
    add("symmetric", 1, 5 * ramp, rest=True)
    add("symmetric", 1, 3 * ramp, rest=True)
    add("asymmetric", 1, 8 * ramp)
    add("asymmetric", 1, 7 * ramp)
    add("multiperiodic", 2, 4 * ramp)
    add("multiperiodic", 3, 2 * ramp)
    add("multiperiodic", 7, 0.5 * ramp)
    add("multiperiodic", 8, 0.5 * ramp)
    for k in range(10):
        add("aperiodic", 0, (0.3 + 0.1 * k) * ramp)
    fr = np.array(fr)
    return SimpleNamespace(alpha=alpha, GIM=0.6 - 0.3 * ramp, IF=0.55 - 0.2 * ramp,
                           block=Block(hb=1.0), forcing=Harmonic(omega=1.3), branches=brs,
                           fractions=lambda: fr, attractor=np.zeros((na, 40, 40), int),
                           settings=dict(alpha_step=0.05))


class _Curve(SimpleNamespace):
    def __len__(self):
        return len(self.omega)


def _chart(law, shift=0.0):
    om = np.linspace(0.8, 3.0, 12)
    al = np.linspace(0.2, 1.2, 10)
    lab = np.full((al.size, om.size), BEHAVIOURS.index("symmetric"))
    lab[al[:, None] > 0.8 + 0.05 * om[None, :] + shift] = BEHAVIOURS.index("overturn")
    lab[al[:, None] < 0.5 / om[None, :]] = BEHAVIOURS.index("rest")
    lab[(al > 0.7) & (al < 0.8), :] = BEHAVIOURS.index("asymmetric")
    if law == "housner":  # one cell of 240 over both laws: a share that rounds to 0 %
        lab[5, 6] = BEHAVIOURS.index("chaotic")
    w = np.linspace(0.9, 2.9, 40)
    curves = [_Curve(type="fold", period=1, omega=w, alpha=0.45 / w + shift, codim2=[],
                     law=law),
              _Curve(type="symmetry_breaking", period=1, omega=w, alpha=0.7 + 0.0 * w + shift,
                     codim2=[], law=law),
              # two period-doubling curves side by side: their labels must not overprint
              _Curve(type="period_doubling", period=1, omega=w, alpha=0.78 + 0.01 * w + shift,
                     codim2=[], law=law),
              _Curve(type="period_doubling", period=2, omega=w, alpha=0.79 + 0.01 * w + shift,
                     codim2=[], law=law)]
    return SimpleNamespace(label=lambda: lab, plane=SimpleNamespace(omega=om, alpha=al),
                           curves=curves, omega_range=(0.8, 3.0), alpha_range=(0.2, 1.2),
                           block=Block(hb=1.0, law=law))


def _spectrum(law):
    from rockjit.ground.response import OUTCOMES
    r = np.linspace(0.5, 8.0, 12)
    k = np.linspace(1.0, 25.0, 10)
    out = np.zeros((r.size, k.size), int)
    mo = 1.0 + 2.0 * r
    out[k[None, :] > mo[:, None]] = OUTCOMES.index("overturn after impact")
    return SimpleNamespace(ratio=r, amplitude=k, outcome=out, min_overturn=mo,
                           min_no_impact=np.full(r.size, np.nan),
                           pulse=SimpleNamespace(kind="sine"), block=Block(hb=4.0, law=law))


def _fragility():
    from rockjit.ground.fitting import fit_lognormal
    x = np.array([0.5, 1.0, 1.5, 2.0, 3.0])
    k = np.array([[0, 2, 5, 8, 10], [0, 0, 0, 0, 0]])
    fits = {}
    for law in ("housner", "mao"):
        fits[law] = {1.0: {}}
        for name in ("overturn", "exceed_0.5", "exceed_1"):
            fits[law][1.0][name] = fit_lognormal(x, k[0], np.full(5, 10)) if law == "housner" \
                else fit_lognormal([3.0], [1], [2])   # one level: unidentified
    frac = (k / 10.0)[:, None, :]  # (law, size, intensity)
    return SimpleNamespace(intensity=x, fraction=lambda name: frac, laws=("housner", "mao"),
                           sizes=(1.0,), fits=fits, measure="pga", records=[0] * 10,
                           block=Block(hb=4.0))


def _builders():
    from rockjit.ground.figures import fig_fragility, fig_rotation, fig_spectrum, fig_transient
    from rockjit.plotting.chart import fig_chart
    from rockjit.study import paper
    cont = _continuation()
    return {
        "fig1": lambda r, g: P.fig_restitution(),
        "fig2": lambda r, g: P.fig_trajectory(r["sym"], rockjit.classify_result(r["sym"])),
        "fig3": lambda r, g: P.fig_gallery({k: r[k] for k in ("rest", "sym", "over")},
                                           {k: rockjit.classify_result(r[k])
                                            for k in ("rest", "sym", "over")}),
        "fig4": lambda r, g: P.fig_laws_timeseries(
            [{"housner": r["sym"], "mao": r["mao"]}],
            [{"housner": rockjit.classify_result(r["sym"]),
              "mao": rockjit.classify_result(r["mao"])}], periods=3),
        "fig5": lambda r, g: paper.draw_fig5(g["sweeps"], 1),
        "fig5_branches": lambda r, g: P.fig_branches(cont),
        "fig5_branches_zoom": lambda r, g: P.fig_branches(cont, limits=(0.9, 1.0)),
        "fig5_one_sweep": lambda r, g: P.fig_bifurcation(g["sweeps"]["housner"]),
        "branches_over_sweep": lambda r, g: P.fig_branches(cont, g["sweeps"]["housner"]),
        "fig6_one_law": lambda r, g: P.fig_basin(g["basins"]["housner"]),
        "fig6": lambda r, g: P.fig_basin_compare(g["basins"]["housner"], g["basins"]["mao"]),
        "fig7": lambda r, g: P.fig_attractors(g["basins"]),
        "fig8": lambda r, g: P.fig_erosion({"housner": _erosion(), "mao": _erosion()}),
        "fig9": lambda r, g: fig_chart({"housner": _chart("housner"),
                                        "mao": _chart("mao", 0.05)}),
        "chart": lambda r, g: fig_chart(_chart("housner")),
        "plane": lambda r, g: P.fig_plane(g["plane"]),
        "plane_second_state": lambda r, g: P.fig_plane(g["plane2"], state=1),
        "fate": lambda r, g: P.fig_fate(g["fate"]),
        "spectrum": lambda r, g: fig_spectrum({"housner": _spectrum("housner"),
                                               "mao": _spectrum("mao")}),
        "fragility": lambda r, g: fig_fragility(_fragility()),
        "rotation": lambda r, g: fig_rotation(_fragility()),
        "transient": lambda r, g: fig_transient(r["pulse"]),
    }


@pytest.mark.parametrize("name", list(_builders()))
def test_every_figure_reads_in_a_journal(runs, grids, name):
    # the default style: the paper's differs only in leaving the figures' titles out
    with style.use("default"):
        fig = _builders()[name](runs, grids)
        assert L.problems(fig) == []


# ---------------------------------------------------------------------------------------------
# what the figures say
# ---------------------------------------------------------------------------------------------

def _legend_texts(fig):
    return [t.get_text() for lg in L._legends(fig) for t in lg.get_texts()]


def test_branches_group_the_long_periods_and_the_zoom_names_only_what_it_shows():
    with style.use("default"):
        whole = P.fig_branches(_continuation())
        zoom = P.fig_branches(_continuation(), limits=(0.9, 1.0))
    texts = _legend_texts(whole)
    periods = [t for t in texts if t.startswith("period") and "doubling" not in t]
    # 1 symmetric, 1 asymmetric, 2, 3, 4 and one entry for 6, 7 and 8
    assert periods == ["period 1, symmetric", "period 1, asymmetric", "period 2", "period 3",
                       "period 4", r"period $\geq 5$"]
    assert "symmetry-breaking pitchfork" in texts and "symmetry-breaking pitchfork" not in \
        _legend_texts(zoom)
    assert not any("grazes" in t for t in _legend_texts(zoom))
    assert "period 1, symmetric" not in _legend_texts(zoom)  # it lies outside the zoom's view
    # the six branches that stop for want of convergence: one entry, each point drawn once
    ends = [t for t in texts if "no convergence" in t]
    assert ends == ["branch ends: no convergence (6 branches)"]
    ax = whole.axes[0]
    crosses = [ln for ln in ax.get_lines() if ln.get_marker() == "x"]
    assert len(crosses) == 1
    pts = np.column_stack(crosses[0].get_data())
    # the distinct cycle points where those branches stop (the two period-8 branches stop at
    # the same eight points, and periods 3 and 4 share two)
    expected = set()
    for br in _continuation().branches:
        if br.ends[0] == "no_convergence":
            expected |= {(round(br.value[0], 9), round(y, 9)) for y in br.cycle[0, :, 1]}
    assert len(pts) == len(expected)


def test_erosion_groups_attractors_by_kind_and_names_aperiodic_as_the_behaviours_page():
    with style.use("default"):
        fig = P.fig_erosion(_erosion())
    texts = _legend_texts(fig)
    stack = [t for t in texts if "up to" in t or t.startswith("overturn")]
    # rest, symmetric rocking, symmetric through rest (2), asymmetric (2), period-2,
    # period-3, periods 7 and 8 together, aperiodic (10), overturn: nine entries for twenty
    # attractors
    assert len(stack) == 9
    assert any(t.startswith(r"period $\geq 5$ (2 attractors)") for t in texts)
    assert any(t.startswith("aperiodic") and "(10 attractors)" in t for t in texts)
    assert any("through rest" in t and "(2 attractors)" in t for t in texts)
    assert not any("chaotic" in t.split("(")[0] for t in texts)


def test_chart_has_no_entry_at_zero_percent_and_letters_its_panels():
    from rockjit.plotting.chart import fig_chart
    with style.use("default"):
        fig = fig_chart({"housner": _chart("housner"), "mao": _chart("mao", 0.05)})
    texts = _legend_texts(fig)
    assert not any(t.endswith(" 0 %") for t in texts) and "chaotic < 1 %" in texts
    assert [ax.get_title(loc="left")[:2] for ax in fig.axes] == ["a)", "b)", "c)"]


def test_a_fit_that_is_not_ok_draws_no_curve_and_no_fit_is_drawn_past_the_data():
    from rockjit.ground.figures import fig_fragility
    res = _fragility()
    with style.use("default"):
        fig = fig_fragility(res)
    ax = fig.axes[0]
    curves = [ln for ln in ax.get_lines() if ln.get_linestyle() != "None"]
    # one law's fit is ok, the other's unidentified: one curve
    assert len(curves) == 1
    x = np.asarray(curves[0].get_xdata(), float)
    assert x.min() >= res.intensity.min() and x.max() <= res.intensity.max()
    assert any("no fit (unidentified)" in t for t in _legend_texts(fig))


def test_the_spectrum_command_draws_a_fine_map_by_default():
    from rockjit.cli.main import build_parser
    args = build_parser().parse_args(["spectrum", "--hb", "4", "--ratio-range", "0.5", "8",
                                      "--amplitude-range", "1", "25", "--out", "x"])
    assert min(args.grid) >= 100


def test_the_headline_image_is_drawn_by_figure_5s_function(monkeypatch, tmp_path):
    """docs/_static/make_headline.py writes the README's image with the function that draws
    the paper's fig5_bifurcation_hb1.png, from the paper's h/b = 1 sweeps."""
    import importlib.util
    import inspect
    from pathlib import Path

    from rockjit.study import paper
    script = Path(__file__).resolve().parents[2] / "docs" / "_static" / "make_headline.py"
    spec = importlib.util.spec_from_file_location("make_headline", script)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    drawn = []
    real = paper.draw_fig5

    def spy(sweeps, hb):
        fig = real(sweeps, hb)
        drawn.append((sorted(sweeps), hb, fig))
        return fig

    monkeypatch.setattr(paper, "draw_fig5", spy)
    out = mod.make(tmp_path / "headline.png", periods=20, alpha_step=0.1)
    assert [(laws, hb) for laws, hb, _ in drawn] == [(["housner", "mao"], 1)]
    fig = drawn[0][2]
    # the file is that figure: its size in pixels is the figure's at the default style's dpi
    from PIL import Image
    with Image.open(out) as im:
        w, h = im.size
    dpi = style.STYLES["default"].rc["savefig.dpi"]
    assert (w, h) == (round(fig.get_figwidth() * dpi), round(fig.get_figheight() * dpi))
    # and the paper draws its figure 5 with the same function
    assert "draw_fig5(" in inspect.getsource(paper._fig5_sweeps)
    # the image in the repository is that figure's size: made by the script, not by hand
    with Image.open(mod.HEADLINE) as im:
        assert im.size[0] == round(fig.get_figwidth() * dpi)


def test_a_figure_drawn_outside_a_style_block_keeps_the_styles_type():
    """A figure function called without ``style.use`` (in a notebook, say, whose matplotlib
    defaults are 10 pt and larger) still sets 7-9 pt type, tick labels included."""
    with matplotlib.rc_context({"font.size": 12.0, "xtick.labelsize": 11.0,
                                "ytick.labelsize": 11.0, "legend.fontsize": 12.0}):
        fig = P.fig_restitution()
        assert L.type_problems(fig) == []
        assert L.canvas_problems(fig) == []
