"""Behaviours, sweeps and basins (issue 4).

Checked against: the hand-checked behaviour gallery of SPEC.md §7 item 3; a slow, readable
NumPy classifier written here from SPEC.md §6 (independent of the compiled one); the exact mirror
symmetry ``(theta, theta', t) -> (-theta, -theta', t + T/2)`` of the equations; the same grid run
with one and two threads; and the full-length runs that early stopping short-cuts.
"""

import math

import numpy as np
import pytest

import rockjit
from rockjit.grids import grids as an

PERIODS = 200


def slow_classify(res, window, tol=1e-6, pmax=16):
    """SPEC.md §6 from a Result's samples, written plainly (no shared code with analysis)."""
    if res.status == "overturned":
        return "overturn", 0
    if res.status == "rest":
        return "rest", 0
    x = res.strobe[window:, :2]
    xh = res.strobe_half[window:, :2]
    scale = max(np.abs(x).max(), np.abs(xh).max())
    for p in range(1, pmax + 1):
        if len(x) <= 2 * p:
            break
        if np.all(np.abs(x[p:] - x[:-p]) <= tol * scale) and \
                np.all(np.abs(xh[p:] - xh[:-p]) <= tol * scale):
            if p > 1:
                return "multiperiodic", p
            n = min(len(x), len(xh))
            sym = np.all(np.abs(xh[:n] + x[:n]) <= tol * scale)
            return ("symmetric" if sym else "asymmetric"), 1
    lam = res.lambda_max
    return ("chaotic" if lam > an.LAM_TOL else "aperiodic"), 0


GALLERY = [
    # (label, hb, alpha, omega, initial state): SPEC.md §7 item 3 and the reference run. The
    # study's multiperiodic example alpha = 0.969 lies in a band of transient chaos where the
    # converged solution overturns (test_transient_chaos_is_resolved); alpha = 0.92 is a robust
    # period-2 orbit of the same family.
    ("rest", 1, 0.15, 1.0, dict(theta0=0.05, dtheta0=0.0, r0=0.0, s0=1.0)),
    ("symmetric", 1, 0.6, 1.3, {}),
    ("asymmetric", 1, 0.8, 1.3, {}),
    ("multiperiodic", 1, 0.92, 1.3, {}),
    ("overturn", 2, 0.448, 1.3, {}),
]


@pytest.mark.parametrize("label, hb, alpha, omega, init", GALLERY, ids=[g[0] for g in GALLERY])
def test_gallery_labels(label, hb, alpha, omega, init):
    """Each gallery run gets its hand-checked label from the compiled sweep kernel (early stop
    and full length), from classify_result, and from the slow classifier."""
    res = rockjit.simulate(hb, alpha, omega, periods=500, lyapunov=True, **init)
    assert slow_classify(res, 400)[0] == label
    assert an.classify_result(res)[0] == label
    z0 = (init["theta0"], init["dtheta0"], init["r0"], init["s0"]) if init else rockjit.Z0_STUDY
    for early in (True, False):
        sw = an.sweep(hb, omega, [alpha], z0=z0, periods=500, early_stop=early)
        assert an.BEHAVIOURS[sw.label[0]] == label


def test_multiperiodic_period_and_chaos():
    """The period of the multiperiodic gallery run matches the slow classifier, and a run in the
    chaotic band (lambda1 > 0, no period) is labelled chaotic by both."""
    res = rockjit.simulate(1, 0.92, 1.3, periods=500, lyapunov=True)
    slow = slow_classify(res, 400)
    sw = an.sweep(1, 1.3, [0.92], periods=500)
    assert slow[0] == "multiperiodic" and sw.period[0] == slow[1] == 2
    res = rockjit.simulate(1, 0.95, 1.3, periods=500, lyapunov=True)
    assert slow_classify(res, 400) == ("chaotic", 0)
    sw = an.sweep(1, 1.3, [0.95], periods=500)
    assert an.BEHAVIOURS[sw.label[0]] == "chaotic" and sw.lambda_max[0] > 0


def test_transient_chaos_is_resolved():
    """At the study's alpha = 0.969 the block wanders chaotically for ~23 periods and overturns.
    Errors grow by ~1e13 over that stretch, so the overturning time is a severe accuracy probe:
    the compiled path converges in N (1024, 2048 and 4096 steps agree to 5e-5, the level at
    which rounding errors amplified by the transient differ between grids; N = 512 is still
    3e-4 away), and DOP853 approaches the same time monotonically as its tolerance tightens."""
    t = {n: rockjit.simulate(1, 0.969, 1.3, periods=30, n_steps=n).t for n in (1024, 2048, 4096)}
    assert max(t.values()) - min(t.values()) < 5e-5
    err = []
    for tol in (1e-10, 1e-12, 1e-13):
        ref = rockjit.simulate(1, 0.969, 1.3, periods=30, method="scipy:DOP853", rtol=tol,
                               atol=tol)
        assert ref.status == "overturned"
        err.append(abs(ref.t - t[2048]))
    assert err[0] > err[1] > err[2] and err[2] < 1e-2


def test_sweep_matches_single_runs():
    """Every cell of a small sweep equals a separate single run (full length, same window)."""
    alphas = np.array([0.55, 0.62, 0.78, 0.85, 0.93, 0.99])
    sw = an.sweep(1, 1.3, alphas, periods=PERIODS, early_stop=False, n_steps=an.GRID_N)
    for a, lab, lam, pts in zip(alphas, sw.label, sw.lambda_max, sw.strobe):
        res = rockjit.simulate(1, a, 1.3, periods=PERIODS, lyapunov=True, n_steps=an.GRID_N)
        assert an.BEHAVIOURS[lab] == slow_classify(res, int(0.8 * PERIODS))[0]
        if res.status == "done":
            assert lam == pytest.approx(res.lyapunov[0], rel=1e-9, abs=1e-12)
            kept = pts[~np.isnan(pts[:, 0])]
            np.testing.assert_array_equal(kept, res.strobe[-len(kept):, :2])


def test_threads_do_not_change_results():
    """A basin computed with one and with two threads is identical, bit for bit."""
    kw = dict(grid=12, periods=100, lyapunov=True)
    one = an.basin(1, 0.66, 1.3, threads=1, **kw)
    two = an.basin(1, 0.66, 1.3, threads=2, **kw)
    np.testing.assert_array_equal(one.label, two.label)
    np.testing.assert_array_equal(one.t_end, two.t_end)
    np.testing.assert_array_equal(one.lambda_max, two.lambda_max)


def test_basin_mirror_symmetry():
    """The equations are invariant under (theta, theta', t) -> (-theta, -theta', t + T/2), i.e.
    a forcing phase shift of pi: the basin at (r0, s0) = (0, -1) is the basin at (0, 1) seen
    through theta0 -> -theta0, theta0' -> -theta0'. The mirror image of an asymmetric orbit is
    its asymmetric twin, so labels map to themselves. Cells on a basin boundary may flip on a
    last-bit difference of the mirrored grid, so a handful may disagree."""
    kw = dict(grid=21, periods=PERIODS)
    up = an.basin(1, 0.8, 1.3, r0=0.0, s0=1.0, **kw)
    down = an.basin(1, 0.8, 1.3, r0=0.0, s0=-1.0, **kw)
    assert len(np.unique(up.label)) >= 2  # a scene with more than one behaviour
    mirrored = up.label[::-1, ::-1]
    agree = np.mean(mirrored == down.label)
    assert agree >= 0.99, f"{100 * (1 - agree):.2f} % of cells break the mirror symmetry"


def test_early_stop_matches_full_length():
    """Early stopping gives the label of the full-length run on a small grid of both laws."""
    for law, hb, alpha, omega in (("housner", 1, 0.66, 1.3), ("mao", 2, 0.2, 1.6)):
        kw = dict(grid=14, periods=PERIODS, law=law)
        early = an.basin(hb, alpha, omega, early_stop=True, **kw)
        full = an.basin(hb, alpha, omega, early_stop=False, **kw)
        assert np.mean(early.label == full.label) >= 0.995
        # and it did stop early somewhere
        assert np.mean(early.t_end) < np.mean(full.t_end)


def test_fractions_cover_every_behaviour():
    b = an.basin(2, 0.2, 1.6, grid=6, periods=60, law="mao")
    fr = b.fractions()
    assert set(fr) == set(an.BEHAVIOURS)
    assert sum(fr.values()) == pytest.approx(100.0)
    for code, name in enumerate(an.BEHAVIOURS):
        assert fr[name] == pytest.approx(100.0 * np.mean(b.label == code))


@pytest.mark.parametrize("kwargs, name", [
    (dict(grid=0), "grid"),
    (dict(theta_range=(-2.0, 2.0)), "theta_range"),
    (dict(theta_range=(1.0, -1.0)), "theta_range"),
    (dict(periods=0), "periods"),
    (dict(tol=2.0), "tol"),
    (dict(threads=0), "threads"),
    (dict(r0=0.3, s0=0.3), "unit circle"),
])
def test_basin_bad_input(kwargs, name):
    with pytest.raises(ValueError, match=name):
        an.basin(1, 0.66, 1.3, **kwargs)


@pytest.mark.parametrize("kwargs, name", [
    (dict(alphas=[-0.1]), "alphas"),
    (dict(alphas=[math.nan]), "alphas"),
    (dict(alpha_range=(0.5, 0.4)), "alpha_range"),
    (dict(alpha_range=(0.5, 0.6), alpha_step=0), "alpha_step"),
    (dict(alphas=[0.6], z0=(0.1, 0.0, 0.0)), "z0"),
])
def test_sweep_bad_input(kwargs, name):
    with pytest.raises(ValueError, match=name):
        an.sweep(1, 1.3, **kwargs)


def test_alpha_grid_includes_end():
    a = an.alpha_grid((0.5, 1.0), 0.001)
    assert a.size == 501 and a[0] == 0.5 and a[-1] == pytest.approx(1.0)


def test_a_sweep_past_overturning_keeps_the_label_and_the_motion():
    # issue 14: the study's Mao hb=1 diagram plotted the motion after the fall
    kw = dict(law="mao", alpha_range=(0.50, 0.62), alpha_step=0.03, periods=200)
    phys = an.sweep(1.0, 1.3, **kw)
    pub = an.sweep(1.0, 1.3, **kw, stop_at_overturn=False)
    np.testing.assert_array_equal(pub.label, phys.label)  # the same labels, overturn kept
    fell = np.isfinite(pub.t_overturn)
    assert fell.any() and not fell.all()
    over = an.BEHAVIOURS.index("overturn")
    assert np.all(phys.label[fell] == over) and np.all(np.isnan(phys.strobe[fell]))
    # ... but the study's way has points and exponents after the fall, of a bounded motion
    assert np.all(np.isfinite(pub.strobe[fell, 0])) and np.all(np.isfinite(pub.lambda_max[fell]))
    assert np.all(pub.motion[fell] != over)
    # where the block never fell, both agree to the bit
    np.testing.assert_array_equal(pub.strobe[~fell], phys.strobe[~fell])
