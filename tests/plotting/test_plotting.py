"""The study's figures: each draws what its inputs say (data, colours, limits, percentages),
with the behaviour it is given (figures classify nothing)."""

import math

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from matplotlib.colors import to_hex  # noqa: E402

import rockjit  # noqa: E402
from rockjit import Block, Harmonic, Integration  # noqa: E402
from rockjit.grids.identity import agreement  # noqa: E402
from rockjit.plotting import figures as P  # noqa: E402
from rockjit.result import BEHAVIOURS, BasinResult, SweepResult, fractions  # noqa: E402
from rockjit.storage.atomic import save_figure  # noqa: E402

# one compiled variant
RUN = dict(integration=Integration(periods=20, n_steps=64), record_stride=4, lyapunov=True)


@pytest.fixture(scope="module")
def ref_run():
    # from the study's z0 (the default state) at the study's forcing point
    return rockjit.simulate(Block(hb=1.0, law="housner"), Harmonic(alpha=0.6, omega=1.3), **RUN)


@pytest.fixture(scope="module")
def short_runs():
    rest = rockjit.simulate(Block(hb=1.0, law="housner"), Harmonic(alpha=0.15, omega=1.0),
                            (0.05, 0.0), **RUN)
    over = rockjit.simulate(Block(hb=2.0, law="housner"), Harmonic(alpha=0.448, omega=1.3),
                            **RUN)
    return {"rest": rest, "overturn": over}


def _sweep():
    """A synthetic sweep using every behaviour, NaN padding, lambda = -inf and nan."""
    n, w = len(BEHAVIOURS) * 2, 5
    alpha = 0.5 + 0.01 * np.arange(n)
    label = np.repeat(np.arange(len(BEHAVIOURS)), 2)
    strobe = np.full((n, w, 2), np.nan)
    rng = np.random.default_rng(0)
    for i, c in enumerate(label):
        if BEHAVIOURS[c] not in ("overturn", "rest", "unresolved"):
            k = 1 + i % w
            strobe[i, :k] = rng.normal(size=(k, 2))
    lam = rng.uniform(-0.5, 0.3, n)
    lam[label == BEHAVIOURS.index("rest")] = -np.inf
    lam[label == BEHAVIOURS.index("overturn")] = np.nan
    return SweepResult(alpha=alpha, label=label, period=np.zeros(n, int), lambda_max=lam,
                       strobe=strobe, impact_section=np.full((n, 1, 2), np.nan),
                       t_end=np.zeros(n), block=Block(hb=1.0), forcing=Harmonic(omega=1.3))


def _basin(law, seed, n=7):
    rng = np.random.default_rng(seed)
    label = rng.integers(0, 4, size=(n, n))
    th = np.linspace(-1, 1, n)
    return BasinResult(theta0=th, dtheta0=np.linspace(-0.5, 0.5, n), label=label,
                       period=np.zeros((n, n), int), lambda_max=None, t_end=np.zeros((n, n)),
                       block=Block(hb=1.0, law=law), forcing=Harmonic(alpha=0.66, omega=1.3),
                       settings=dict(r0=0.0, s0=1.0))


def _scatter_points(ax):
    return sum(c.get_offsets().shape[0] for c in ax.collections
               if hasattr(c, "get_offsets") and c.get_offsets().ndim == 2)


def test_one_colour_per_behaviour():
    assert set(P.BEHAVIOUR_COLOURS) == set(BEHAVIOURS)
    assert len({to_hex(c) for c in P.BEHAVIOUR_COLOURS.values()}) == len(BEHAVIOURS)


def test_restitution_curves_and_marks():
    fig = P.fig_restitution((1 / math.sqrt(2), 4.0), n=50)
    ax = fig.axes[0]
    lines = [ln for ln in ax.get_lines() if len(ln.get_xdata()) == 50]
    thc = np.radians(lines[0].get_xdata())
    np.testing.assert_allclose(lines[0].get_ydata(), rockjit.e_housner(thc))
    np.testing.assert_allclose(lines[1].get_ydata(), rockjit.e_mao(thc))
    texts = " ".join(t.get_text() for a in fig.axes for t in a.texts)
    assert "0.250" in texts and "0.582" in texts and "79.85" in texts and "17.03" in texts
    with pytest.raises(ValueError, match="hb_range"):
        P.fig_restitution((0.5, 2.0))


def test_trajectory_figure(ref_run, tmp_path):
    beh = rockjit.classify_result(ref_run)
    fig = P.fig_trajectory(ref_run, beh)
    ax_t, ax_last, ax_l, ax_p = fig.axes[:4]
    # theta(t) over the first periods: the recorded samples there, and every impact inserted
    # as two points at theta = 0 (the vertical jump)
    T = ref_run.period
    t, th, _ = P.with_impacts(ref_run, 0.0, 8 * T)
    np.testing.assert_array_equal(ax_t.get_lines()[0].get_xdata(), t)
    np.testing.assert_array_equal(ax_t.get_lines()[0].get_ydata(), th)
    tr = ref_run.trajectory
    inside = tr[tr[:, 0] <= 8 * T]
    assert np.isin(inside[:, 1], th).all()
    n_imp = np.count_nonzero(ref_run.impacts[:, 0] <= 8 * T)
    assert th.size == inside.shape[0] + 2 * n_imp and n_imp > 0
    # ... and over the last periods, up to the end
    assert ax_last.get_lines()[0].get_xdata().max() == pytest.approx(ref_run.t)
    lam = ax_l.get_lines()[0]
    k = np.arange(1, ref_run.lyapunov_running.shape[0])
    np.testing.assert_allclose(lam.get_xdata(), k * ref_run.period)
    np.testing.assert_array_equal(lam.get_ydata(), ref_run.lyapunov_running[1:, 0])
    # phase portrait: the asymptotic window only
    xs = ax_p.get_lines()[0].get_xdata()
    _, w, _ = P.with_impacts(ref_run, ref_run.window[0])
    np.testing.assert_array_equal(xs, w)
    assert 0 < len(xs) < ref_run.trajectory.shape[0]
    assert "symmetric" in fig.get_suptitle()
    # drawn in the behaviour's colour
    assert to_hex(ax_t.get_lines()[0].get_color()) == to_hex(P.BEHAVIOUR_COLOURS["symmetric"])
    save_figure(fig, tmp_path / "t.png")
    assert (tmp_path / "t.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_trajectory_needs_a_trajectory(ref_run):
    import dataclasses
    with pytest.raises(ValueError, match="record_stride"):
        P.fig_trajectory(dataclasses.replace(ref_run, trajectory=None), ("symmetric", 1))


def test_impacts_are_vertical_jumps(ref_run):
    t, th, dth = P.with_impacts(ref_run)
    at = np.flatnonzero(np.isin(t, ref_run.impacts[:, 0]))
    assert at.size == 2 * ref_run.impacts.shape[0]
    # each impact: two points at theta = 0, the same instant, theta'- then theta'+
    np.testing.assert_array_equal(th[at], 0.0)
    np.testing.assert_array_equal(dth[at[0::2]], ref_run.impacts[:, 1])
    np.testing.assert_array_equal(dth[at[1::2]], ref_run.impacts[:, 2])
    assert np.all(np.diff(t) >= 0)


def test_gallery_titles_carry_the_classification(ref_run, short_runs):
    runs = {"sym": ref_run, **short_runs}
    beh = {k: rockjit.classify_result(r) for k, r in runs.items()}
    fig = P.fig_gallery(runs, beh)
    titles = [sub.get_suptitle() for sub in fig.subfigs]
    assert len(titles) == 3
    assert titles[0].startswith("a) sym") and "symmetric" in titles[0]
    assert titles[1].startswith("b) rest") and "at rest from" in titles[1]
    assert titles[2].startswith("c) overturn") and "overturns at" in titles[2]
    # the behaviour given is the one drawn: a figure classifies nothing itself
    fig = P.fig_gallery({"sym": ref_run}, {"sym": ("chaotic", 0)})
    assert "chaotic" in fig.subfigs[0].get_suptitle()
    assert to_hex(fig.axes[0].get_lines()[0].get_color()) == to_hex(
        P.BEHAVIOUR_COLOURS["chaotic"])


def test_laws_timeseries(short_runs, ref_run):
    row = {"housner": ref_run, "mao": short_runs["rest"]}
    beh = [{law: rockjit.classify_result(r) for law, r in row.items()}]
    fig = P.fig_laws_timeseries([row], beh, periods=3)
    ax_h, ax_m = (ax for ax in fig.axes if "\\theta$" in ax.get_ylabel()
                  and ax.get_ylabel().count("\n"))
    # the run that went on: its last 3 periods, where it has settled, up to its end
    x = np.concatenate([np.asarray(ln.get_xdata(), float) for ln in ax_h.get_lines()
                        if len(ln.get_xdata()) > 2])
    assert x.min() >= ref_run.t - 3 * ref_run.period - 1e-12
    assert x.max() == pytest.approx(ref_run.t)
    # the run that came to rest: the whole of it
    rest = short_runs["rest"]
    x = np.asarray(ax_m.get_lines()[0].get_xdata(), float)
    assert x.min() == pytest.approx(0.0) and x.max() == pytest.approx(rest.t)
    assert ax_h.get_ylabel().startswith("Housner") and ax_m.get_ylabel().startswith("Housner")
    # what each run does is said in its phase portrait's title; no caption inside the image
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert titles == ["Housner:\nsymmetric, $p = 1$", f"Housner:\nat rest from $t = {rest.t:.3g}$"]
    assert fig.subfigs[0].get_supxlabel() == ""


def test_bifurcation_draws_every_finite_point_and_clips_rest():
    sw = _sweep()
    fig = P.fig_bifurcation(sw)
    ax, ax_s, ax_l = fig.axes[:3]
    assert _scatter_points(ax) == np.isfinite(sw.strobe[:, :, 1]).sum()
    # the strip holds every alpha's code
    np.testing.assert_array_equal(np.asarray(ax_s.collections[0].get_array()).ravel(),
                                  sw.label)
    lo = ax_l.get_ylim()[0]
    rest = sw.label == BEHAVIOURS.index("rest")
    marks = [c.get_offsets() for c in ax_l.collections if len(c.get_offsets())]
    bottom = np.concatenate([m for m in marks if np.allclose(m[:, 1], lo)])
    np.testing.assert_allclose(np.sort(bottom[:, 0]), np.sort(sw.alpha[rest]))
    # finite exponents all drawn, nan ones skipped
    n_fin = np.isfinite(sw.lambda_max).sum()
    assert sum(len(m) for m in marks) == n_fin + rest.sum()
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend == list(BEHAVIOURS) + [r"$\lambda = -\infty$ (through rest)"]


def test_bifurcation_zoom_and_pair():
    sw = _sweep()
    fig = P.fig_bifurcation(sw, alpha_limits=(0.55, 0.6))
    assert fig.axes[0].get_xlim() == pytest.approx((0.55, 0.6))
    inside = (sw.alpha >= 0.55 - 1e-12) & (sw.alpha <= 0.6 + 1e-12)
    assert _scatter_points(fig.axes[0]) == np.isfinite(sw.strobe[inside, :, 1]).sum()
    fig = P.fig_bifurcation({"a": sw, "b": sw})
    assert len(fig.axes) == 6


def test_basin_image_orientation_and_percentages():
    b = _basin("housner", 1)
    b.label[0, -1] = 5  # theta0 = -1, dtheta0 = +0.5: the upper-left corner
    fig = P.fig_basin(b)
    ax = fig.axes[0]
    im = ax.images[0]
    np.testing.assert_array_equal(im.get_array(), b.label.T)
    assert im.origin == "lower"
    x0, x1, y0, y1 = im.get_extent()
    assert x0 < -1 < x1 and y0 < -0.5 and 0.5 < y1
    fr = fractions(b.label)
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend == [f"{n} {fr[n]:.1f} %" for n in BEHAVIOURS if fr[n] > 0]


def test_basin_compare_agreement():
    a, b = _basin("housner", 1), _basin("mao", 2)
    fig = P.fig_basin_compare(a, b)
    pct = 100.0 * np.mean(a.label == b.label)
    assert f"{pct:.1f} %" in fig.axes[2].get_title(loc="left")
    np.testing.assert_array_equal(fig.axes[2].images[0].get_array(),
                                  (a.label == b.label).T.astype(int))
    assert agreement(a.label, b.label) == pytest.approx(pct)
    with pytest.raises(ValueError, match="same grid"):
        P.fig_basin_compare(a, _basin("mao", 2, n=5))


def test_cell_edges_and_extent():
    from rockjit.plotting import cells
    x = np.array([0.3, 0.5, 0.6, 1.0])
    # the midpoints, and beyond each end as far as the nearest midpoint is inside it
    np.testing.assert_allclose(cells.edges(x), [0.2, 0.4, 0.55, 0.8, 1.2], rtol=0, atol=1e-15)
    # a single point: half a unit either side by default, ``lone`` when given, or a share of
    # itself when positive and ``lone_ratio`` is given (a log axis)
    assert cells.edges([0.7]).tolist() == [0.7 - 0.5, 0.7 + 0.5]
    assert cells.edges([0.0]).tolist() == [-0.5, 0.5]
    assert cells.edges([0.7], lone=0.5e-3).tolist() == [0.7 - 0.5e-3, 0.7 + 0.5e-3]
    assert cells.edges([2.0], lone_ratio=0.1).tolist() == [1.8, 2.2]
    assert cells.edges([-2.0], lone_ratio=0.1).tolist() == [-2.5, -1.5]
    # an image's extent: half a step beyond the ends, half a unit for a single point
    assert cells.extent(np.array([1.0, 2.0, 3.0]), np.array([4.0])) == (0.5, 3.5, 3.5, 4.5)
