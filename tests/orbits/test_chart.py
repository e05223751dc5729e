"""The forcing plane with exact boundaries (rockjit.chart, rockjit.orbits.curves): bifurcation
curves in (alpha, omega) against the one-parameter location along alpha, independent shooting,
the brute-force chart, the model's mirror symmetry; refusals; the command line's files."""

import json
import math

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic
from rockjit.orbits import (Bifurcation, ChartCurves, ContinuationSettings, CurveSettings,
                            OrbitRefused, Shooting, continue_branches, continue_curve,
                            periodic_orbit, relocate)

ALPHA, OMEGA = (0.2, 1.2), (0.8, 3.0)
STUDY_OMEGA = {1: 1.3, 2: 1.6}
CRIT = {"fold": 1.0, "symmetry_breaking": 1.0, "period_doubling": -1.0}


@pytest.fixture(scope="module")
def hb1():
    """The h/b = 1 Housner chart (coarse: the curves do not depend on the chart's grid)."""
    return rockjit.chart(Block(hb=1), ALPHA, OMEGA, grid=(80, 80))


@pytest.fixture(scope="module")
def charts(hb1):
    """Both laws at both slendernesses (h/b = 1 Housner: the fixture above)."""
    out = {(1, "housner"): hb1}
    for hb, law in ((1, "mao"), (2, "housner"), (2, "mao")):
        out[(hb, law)] = rockjit.chart(Block(hb=hb, law=law), ALPHA, OMEGA, grid=(40, 40))
    return out


def of(res, kind, period=None):
    return [c for c in res.curves if c.type == kind and (period is None or c.period == period)]


# --------------------------------------------------------------------------- the curves

def test_hb1_housner_has_every_period_one_and_two_curve(hb1):
    found = sorted((c.type, c.period) for c in hb1.curves)
    assert found == [("fold", 1), ("grazing", 1), ("period_doubling", 1),
                     ("period_doubling", 2), ("symmetry_breaking", 1)]
    for c in hb1.curves:
        # each followed edge to edge of the chart, through the five seed lines it crosses
        assert c.ends == ("range", "range"), (c.type, c.ends)
        a, w = c.alpha, c.omega
        for end in (0, -1):
            assert (math.isclose(a[end], ALPHA[0], abs_tol=1e-12) or
                    math.isclose(a[end], ALPHA[1], abs_tol=1e-12) or
                    math.isclose(w[end], OMEGA[0], abs_tol=1e-12) or
                    math.isclose(w[end], OMEGA[1], abs_tol=1e-12))
    # every seed on a line is either a curve's own or lies on one found from another line
    assert all("curve" in s for s in hb1.seeds)


def test_every_point_relocated_along_alpha_to_1e8(hb1):
    """Each point of each curve, located again by the one-parameter continuation in alpha at
    its omega (Brent's method on det(M -+ I); bisection for the grazing), agrees to 1e-8."""
    worst = {}
    for c in hb1.curves:
        errs = [abs(relocate(c, k) - c.alpha[k]) for k in range(len(c))]
        assert np.all(np.isfinite(errs)), (c.type, c.period)
        worst[(c.type, c.period)] = max(errs)
    assert max(worst.values()) <= 1e-8, worst


def test_curves_pass_through_the_points_located_at_the_study_omega(charts):
    """The study's omega (1.3 for h/b = 1, 1.6 for h/b = 2) is none of the seed lines: the
    located bifurcations of a continuation along alpha there lie on the curves."""
    checked = 0
    for (hb, law), res in charts.items():
        w = STUDY_OMEGA[hb]
        assert all(abs(s - w) > 0.05 for s in res.seed_omegas)
        cont = continue_branches(Block(hb=hb, law=law), Harmonic(omega=w), ALPHA,
                                 sweep_step=0.005,
                                 settings=ContinuationSettings(max_period=2))
        for b in cont.bifurcations:
            if b.period > 2:
                continue
            on = [a for c in of(res, b.type, b.period) for a in c.solve_at(w)]
            assert on, (hb, law, b.type, b.period)
            assert min(abs(a - b.alpha) for a in on) <= 1e-8, (hb, law, b.type, b.alpha, on)
            checked += 1
    assert checked >= 19


def test_condition_and_fixed_point_hold_along_each_curve(charts):
    for res in charts.values():
        for c in res.curves:
            # what the extended system reports: the residual of each equation
            assert np.max(c.residual) <= 1e-9 * max(1.0, float(np.abs(c.multipliers).max()))
            if c.type == "grazing":
                assert np.max(np.abs(c.condition)) <= 1e-11
                continue
            assert np.max(c.critical) <= 1e-8, (c.type, c.period, np.max(c.critical))
            # independent: shooting at sampled points (its own Newton at fixed forcing) finds
            # the orbit with a multiplier on +1 (-1)
            for k in np.linspace(0, len(c) - 1, 4).astype(int):
                o = periodic_orbit(res.block, Harmonic(alpha=c.alpha[k], omega=c.omega[k],
                                                       phase=c.phase),
                                   c.state[k], c.period, shooting=Shooting(graze_tol=0))
                assert np.abs(o.state - c.state[k]).max() <= 1e-9
                crit = CRIT[c.type]
                assert np.min(np.abs(o.multipliers - crit)) <= 1e-7, (c.type, o.multipliers)


def test_grazing_curve_orbits_touch_theta_zero(hb1):
    """Independent of the Hermite refinement: a plain run of the orbit on a 64 times finer
    grid turns back at |theta| below 1e-8 of its size without an impact there."""
    c = of(hb1, "grazing", 1)[0]
    assert c.grazing == "impact"
    for k in np.linspace(0, len(c) - 1, 4).astype(int):
        r = rockjit.simulate(hb1.block, Harmonic(alpha=c.alpha[k], omega=c.omega[k],
                                                 phase=c.phase),
                             c.state[k], integration=rockjit.Integration(
                                 periods=1, n_steps=384 * 64), record_stride=1)
        assert r.n_impacts == c.impacts[k]
        th = r.trajectory[:, 1]
        same = (th[:-2] * th[1:-1] > 0) & (th[1:-1] * th[2:] > 0)
        turn = same & (np.abs(th[1:-1]) <= np.abs(th[:-2])) & \
            (np.abs(th[1:-1]) <= np.abs(th[2:]))
        depth = np.abs(th[1:-1][turn]).min()
        assert depth <= 1e-8 * np.abs(th).max()


def test_the_chart_changes_behaviour_across_each_curve(hb1):
    """Cells of the brute-force chart on either side of each curve of a stable orbit (the
    grazing curve's orbit is unstable: the chart does not see it), a cell away from it."""
    lab = hb1.label()
    per = np.asarray(hb1.plane.period)[0]
    alphas, omegas = np.asarray(hb1.plane.alpha), np.asarray(hb1.plane.omega)
    da = alphas[1] - alphas[0]
    over = rockjit.BEHAVIOURS.index("overturn")
    for c in hb1.curves:
        if c.type == "grazing":
            continue
        changed = total = 0
        for j, w in enumerate(omegas):
            for a in c.alpha_at(w):
                lo = np.nonzero(alphas < a - da)[0]
                hi = np.nonzero(alphas > a + da)[0]
                if lo.size == 0 or hi.size == 0:
                    continue
                i0, i1 = lo[-1], hi[0]
                if over in (lab[i0, j], lab[i1, j]):
                    continue
                total += 1
                changed += (lab[i0, j], per[i0, j]) != (lab[i1, j], per[i1, j])
        assert total >= 15, (c.type, c.period, total)
        assert changed >= 0.8 * total, (c.type, c.period, changed, total)


def test_mirror_image_gives_the_same_curve(hb1):
    """Both laws are symmetric under theta -> -theta with the forcing shifted by half a
    period: the period doubling of the mirror orbit -x(T/2) lies on the same curve."""
    c = of(hb1, "period_doubling", 1)[0]
    k = len(c) // 2
    seed = Bifurcation(type="period_doubling", parameter="alpha", value=c.alpha[k],
                       alpha=c.alpha[k], omega=c.omega[k], period=1, multipliers=c.multipliers[k],
                       state=-c.cycle_half[k, 0], cycle=-c.cycle_half[k], cycle_half=-c.cycle[k],
                       branch=0, neighbours=(c.alpha[k], c.alpha[k]),
                       neighbour_multipliers=np.array([c.multipliers[k]] * 2), located=True,
                       n_simulate=0, has_mirror=True)
    m = continue_curve(hb1.block, seed, phase=c.phase, alpha_range=ALPHA, omega_range=OMEGA)
    for w in (1.0, 1.5, 2.0, 2.5):
        a, b = c.solve_at(w), m.solve_at(w)
        assert len(a) == len(b) == 1 and abs(a[0] - b[0]) <= 1e-9, (w, a, b)
    # the mirror curve's orbits are the mirror images of the curve's
    i = int(np.argmin(np.hypot(m.alpha - c.alpha[k], m.omega - c.omega[k])))
    assert np.abs(m.state[i] + c.cycle_half[k, 0]).max() <= 1e-6
    assert np.allclose(np.sort(np.abs(m.multipliers[i])), np.sort(np.abs(c.multipliers[k])),
                       rtol=1e-6)


# --------------------------------------------------------------------------- refusals

def test_refusals():
    # ranges that contain no seed: nothing bifurcates on the lines (the block rests)
    with pytest.raises(ValueError, match="contain no seed"):
        rockjit.chart(Block(hb=1), (0.2, 0.25), (0.8, 0.9), grid=(3, 3))
    with pytest.raises(ValueError, match="seed_omegas must lie in omega_range"):
        rockjit.chart.plan(Block(hb=1), ALPHA, OMEGA, curves=ChartCurves(seed_omegas=[0.5]))
    with pytest.raises(ValueError, match="types"):
        ChartCurves(types=("neimark_sacker",))
    with pytest.raises(ValueError, match="max_period"):
        ChartCurves(max_period=0)
    with pytest.raises(ValueError, match="curves must be"):
        rockjit.chart.plan(Block(hb=1), ALPHA, OMEGA, curves=CurveSettings())
    with pytest.raises(ValueError, match="start < end"):
        rockjit.chart.plan(Block(hb=1), (0.5, 0.5), OMEGA)
    with pytest.raises(ValueError, match="follow must be"):
        ChartCurves(follow=ContinuationSettings())
    with pytest.raises(ValueError, match="max_multiplier"):
        CurveSettings(max_multiplier=1.0)
    # a curve asked for outside the chart
    cont = continue_branches(Block(hb=1), Harmonic(omega=1.3), (0.5, 0.85), sweep_step=0.01,
                             settings=ContinuationSettings(max_period=1, switch=False))
    sb = next(b for b in cont.bifurcations if b.type == "symmetry_breaking")
    graze = next(b for b in cont.bifurcations if b.type == "grazing")
    with pytest.raises(ValueError, match="lies outside the chart"):
        continue_curve(Block(hb=1), sb, phase=cont.phase, alpha_range=(0.2, 0.7),
                       omega_range=OMEGA)
    with pytest.raises(ValueError, match="lies outside the chart"):
        continue_curve(Block(hb=1), sb, phase=cont.phase, alpha_range=ALPHA,
                       omega_range=(1.4, 3.0))
    with pytest.raises(ValueError, match="seed must be"):
        continue_curve(Block(hb=1), "sb", phase=0.0, alpha_range=ALPHA, omega_range=OMEGA)
    ns = Bifurcation(**{**sb.__dict__, "type": "neimark_sacker"})
    with pytest.raises(ValueError, match="not continued"):
        continue_curve(Block(hb=1), ns, phase=cont.phase, alpha_range=ALPHA,
                       omega_range=OMEGA)
    # a curve of an orbit too unstable to follow (the grazing's orbit has |mu| = 93)
    with pytest.raises(OrbitRefused, match="unstable"):
        continue_curve(Block(hb=1), graze, phase=cont.phase, alpha_range=ALPHA,
                       omega_range=OMEGA, settings=CurveSettings(max_multiplier=50))


def test_a_curve_ends_at_the_chart_edge_it_meets(hb1):
    c = of(hb1, "symmetry_breaking", 1)[0]
    cut = continue_curve(hb1.block, _seed_of(c, 1.5), phase=c.phase, alpha_range=ALPHA,
                         omega_range=(1.2, 2.0))
    assert cut.ends == ("range", "range")
    assert math.isclose(cut.omega.min(), 1.2, abs_tol=1e-12)
    assert math.isclose(cut.omega.max(), 2.0, abs_tol=1e-12)
    assert np.all((cut.omega >= 1.2 - 1e-12) & (cut.omega <= 2.0 + 1e-12))


def _seed_of(curve, omega):
    """A Bifurcation at the curve's point nearest ``omega``."""
    k = int(np.argmin(np.abs(curve.omega - omega)))
    return Bifurcation(type=curve.type, parameter="alpha", value=curve.alpha[k],
                       alpha=curve.alpha[k], omega=curve.omega[k], period=curve.period,
                       multipliers=curve.multipliers[k], state=curve.state[k],
                       cycle=curve.cycle[k], cycle_half=curve.cycle_half[k], branch=0,
                       neighbours=(curve.alpha[k],) * 2,
                       neighbour_multipliers=np.array([curve.multipliers[k]] * 2),
                       located=True, n_simulate=0, has_mirror=not curve.symmetric)


# --------------------------------------------------------------------------- outputs

def test_command_line_writes_the_curves(tmp_path):
    from rockjit.cli.main import main
    out = tmp_path / "chart"
    rc = main(["chart", "--hb", "1", "--law", "both", "--alpha-range", "0.2", "1.2",
               "--omega-range", "0.8", "3", "--grid", "12", "10", "--max-period", "1",
               "--seed-omegas", "1.2", "--quiet", "--out", str(out)])
    assert rc == 0
    s = json.loads((out / "summary.json").read_text())
    laws = {c["law"] for c in s["curves"]}
    assert laws == {"housner", "mao"}
    for c in s["curves"]:
        assert c["type"] in ("fold", "symmetry_breaking", "period_doubling", "grazing")
        assert c["period"] == 1
        pts = np.asarray(c["points"])
        assert pts.ndim == 2 and pts.shape[1] == 2 and pts.shape[0] == c["n_points"]
        assert np.all((pts[:, 0] >= 0.2 - 1e-12) & (pts[:, 0] <= 1.2 + 1e-12))
    assert set(s["charts"]) == {"housner", "mao"}
    z = np.load(out / "chart.npz")
    assert z["label_housner"].shape == z["label_mao"].shape == (12, 10)
    assert z["curve_type"].shape == (len(s["curves"]),)
    for i, c in enumerate(s["curves"]):
        assert np.allclose(np.stack([z[f"curve{i}_alpha"], z[f"curve{i}_omega"]], 1),
                           c["points"])
    assert (out / "chart.png").stat().st_size > 0


def test_fig_chart_styles_and_labels(hb1):
    from rockjit.plotting.chart import CURVE_STYLES, fig_chart
    fig = fig_chart(hb1)
    ax = fig.axes[0]
    texts = {t.get_text() for t in ax.texts}
    assert texts == {"F\u2081", "SB\u2081", "PD\u2081", "PD\u2082", "G\u2081"}
    # each curve drawn in its type's style, the four styles distinct
    gids = {ln.get_gid() for ln in ax.get_lines() if ln.get_gid()}
    assert gids == {f"{c.type}:{c.period}:housner" for c in hb1.curves}
    assert len({str(s) for s in CURVE_STYLES.values()}) == 4
    fig2 = fig_chart({"housner": hb1, "mao": hb1})
    assert len(fig2.axes) == 3
