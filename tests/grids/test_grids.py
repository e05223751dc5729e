"""Behaviours, sweeps and basins.

Checked against: the hand-checked behaviour gallery of docs/theory/study.md item 3; a slow, readable
NumPy classifier written here from docs/theory/behaviours.md (independent of the compiled one); the exact mirror
symmetry ``(theta, theta', t) -> (-theta, -theta', t + T/2)`` of the equations; the same grid run
with one and two threads; and the full-length runs that early stopping short-cuts.
"""

import math

import numpy as np
import pytest

import rockjit
from rockjit import (BEHAVIOURS, Block, Classification, Execution, Harmonic, Integration,
                     Lattice, Scipy)
from rockjit.grids.plan import GRID_N

PERIODS = 200


def slow_classify(res, window, tol=1e-6, pmax=16):
    """docs/theory/behaviours.md from a Result's samples, written plainly (nothing shared with the compiled
    classifier)."""
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
    return ("chaotic" if lam > Classification().lam_tol else "aperiodic"), 0


GALLERY = [
    # (label, hb, alpha, omega, initial state): docs/theory/study.md item 3 and the reference run. The
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
    state = (init["theta0"], init["dtheta0"]) if init else None  # None: the study's z0
    forcing = Harmonic(omega=omega, **{k: v for k, v in init.items() if k in ("r0", "s0")})
    integration = Integration(periods=500)
    res = rockjit.simulate(Block(hb), forcing.replace(alpha=alpha), state,
                           integration=integration, lyapunov=True)
    assert slow_classify(res, 400)[0] == label
    assert rockjit.classify_result(res)[0] == label
    for early in (True, False):
        sw = rockjit.sweep(Block(hb), forcing, [alpha], state, integration=integration,
                           classification=Classification(early_stop=early))
        assert BEHAVIOURS[sw.label[0]] == label


def test_multiperiodic_period_and_chaos():
    """The period of the multiperiodic gallery run matches the slow classifier, and a run in the
    chaotic band (lambda1 > 0, no period) is labelled chaotic by both."""
    block, forcing, integration = Block(1), Harmonic(omega=1.3), Integration(periods=500)
    res = rockjit.simulate(block, forcing.replace(alpha=0.92), integration=integration,
                           lyapunov=True)
    slow = slow_classify(res, 400)
    sw = rockjit.sweep(block, forcing, [0.92], integration=integration)
    assert slow[0] == "multiperiodic" and sw.period[0] == slow[1] == 2
    res = rockjit.simulate(block, forcing.replace(alpha=0.95), integration=integration,
                           lyapunov=True)
    assert slow_classify(res, 400) == ("chaotic", 0)
    sw = rockjit.sweep(block, forcing, [0.95], integration=integration)
    assert BEHAVIOURS[sw.label[0]] == "chaotic" and sw.lambda_max[0] > 0


def test_a_period_two_orbit_just_past_its_doubling():
    """Just past the period doubling at alpha = 0.9115 the two points of the period-2 orbit lie
    only 8 % of the orbit's size apart (alpha = 0.912; measured): the period test, at its
    tolerance of 1e-6 of that size, must still tell them apart, as the slow classifier does."""
    block, forcing, integration = Block(1), Harmonic(omega=1.3), Integration(periods=500)
    res = rockjit.simulate(block, forcing.replace(alpha=0.912), integration=integration,
                           lyapunov=True)
    x = res.strobe[400:, :2]
    assert 0.05 < np.abs(x[-1] - x[-2]).max() / np.abs(x).max() < 0.1  # the case it is
    assert slow_classify(res, 400) == ("multiperiodic", 2)
    assert rockjit.classify_result(res) == ("multiperiodic", 2)
    sw = rockjit.sweep(block, forcing, [0.912], integration=integration)
    assert BEHAVIOURS[sw.label[0]] == "multiperiodic" and sw.period[0] == 2


def test_transient_chaos_is_resolved():
    """At the study's alpha = 0.969 the block wanders chaotically for ~23 periods and overturns.
    Errors grow by ~1e13 over that stretch, so the overturning time is a severe accuracy probe:
    the compiled path converges in N (1024, 2048 and 4096 steps agree to 5e-5, the level at
    which rounding errors amplified by the transient differ between grids; N = 512 is still
    3e-4 away), and DOP853 approaches the same time monotonically as its tolerance tightens."""
    run = (Block(1), Harmonic(alpha=0.969, omega=1.3))
    t = {n: rockjit.simulate(*run, integration=Integration(periods=30, n_steps=n)).t
         for n in (1024, 2048, 4096)}
    assert max(t.values()) - min(t.values()) < 5e-5
    err = []
    for tol in (1e-10, 1e-12, 1e-13):
        ref = rockjit.simulate(*run, integration=Integration(periods=30),
                               method=Scipy("DOP853", rtol=tol, atol=tol))
        assert ref.status == "overturned"
        err.append(abs(ref.t - t[2048]))
    assert err[0] > err[1] > err[2] and err[2] < 1e-2


def test_sweep_matches_single_runs():
    """Every cell of a small sweep equals a separate single run (full length, same window)."""
    alphas = np.array([0.55, 0.62, 0.78, 0.85, 0.93, 0.99])
    integration = Integration(periods=PERIODS, n_steps=GRID_N)
    sw = rockjit.sweep(Block(1), Harmonic(omega=1.3), alphas, integration=integration,
                       classification=Classification(early_stop=False))
    # lambda_window is the finite-window estimate a single run averages (lambda_max is the
    # exact Floquet exponent where a cell is periodic: tests/grids/test_exact_exponents.py)
    for a, lab, lam, pts in zip(alphas, sw.label, sw.lambda_window, sw.strobe):
        res = rockjit.simulate(Block(1), Harmonic(alpha=a, omega=1.3), integration=integration,
                               lyapunov=True)
        assert BEHAVIOURS[lab] == slow_classify(res, int(0.8 * PERIODS))[0]
        if res.status == "done":
            assert lam == pytest.approx(res.lyapunov[0], rel=1e-9, abs=1e-12)
            kept = pts[~np.isnan(pts[:, 0])]
            np.testing.assert_array_equal(kept, res.strobe[-len(kept):, :2])


def test_threads_do_not_change_results():
    """A basin computed with one and with two threads is identical, bit for bit."""
    kw = dict(integration=Integration(periods=100), lyapunov=True)
    one = rockjit.basin(Block(1), Harmonic(alpha=0.66, omega=1.3), 12,
                        execution=Execution(threads=1), **kw)
    two = rockjit.basin(Block(1), Harmonic(alpha=0.66, omega=1.3), 12,
                        execution=Execution(threads=2), **kw)
    np.testing.assert_array_equal(one.label, two.label)
    np.testing.assert_array_equal(one.t_end, two.t_end)
    np.testing.assert_array_equal(one.lambda_max, two.lambda_max)
    np.testing.assert_array_equal(one.lambda_window, two.lambda_window)


def test_basin_mirror_symmetry():
    """The equations are invariant under (theta, theta', t) -> (-theta, -theta', t + T/2), i.e.
    a forcing phase shift of pi: the basin at (r0, s0) = (0, -1) is the basin at (0, 1) seen
    through theta0 -> -theta0, theta0' -> -theta0'. The mirror image of an asymmetric orbit is
    its asymmetric twin, so labels map to themselves. Cells on a basin boundary may flip on a
    last-bit difference of the mirrored grid, so a handful may disagree."""
    kw = dict(grid=21, integration=Integration(periods=PERIODS))
    up = rockjit.basin(Block(1), Harmonic(alpha=0.8, omega=1.3, r0=0.0, s0=1.0), **kw)
    down = rockjit.basin(Block(1), Harmonic(alpha=0.8, omega=1.3, r0=0.0, s0=-1.0), **kw)
    assert len(np.unique(up.label)) >= 2  # a scene with more than one behaviour
    mirrored = up.label[::-1, ::-1]
    agree = np.mean(mirrored == down.label)
    assert agree >= 0.99, f"{100 * (1 - agree):.2f} % of cells break the mirror symmetry"


def test_early_stop_matches_full_length():
    """Early stopping gives the label of the full-length run on a small grid of both laws."""
    for law, hb, alpha, omega in (("housner", 1, 0.66, 1.3), ("mao", 2, 0.2, 1.6)):
        kw = dict(grid=14, integration=Integration(periods=PERIODS))
        run = (Block(hb, law), Harmonic(alpha=alpha, omega=omega))
        early = rockjit.basin(*run, classification=Classification(early_stop=True), **kw)
        full = rockjit.basin(*run, classification=Classification(early_stop=False), **kw)
        assert np.mean(early.label == full.label) >= 0.995
        # and it did stop early somewhere
        assert np.mean(early.t_end) < np.mean(full.t_end)


def test_fractions_cover_every_behaviour():
    b = rockjit.basin(Block(2, "mao"), Harmonic(alpha=0.2, omega=1.6), grid=6,
                      integration=Integration(periods=60))
    fr = b.fractions()
    assert set(fr) == set(BEHAVIOURS)
    assert sum(fr.values()) == pytest.approx(100.0)
    for code, name in enumerate(BEHAVIOURS):
        assert fr[name] == pytest.approx(100.0 * np.mean(b.label == code))


# every bad value with an otherwise small grid, so that a refusal that does not happen costs
# little: (what to change in the basin's call, regular expression its message must match)
BASIN = dict(grid=4, integration=dict(periods=2), classification={}, execution={},
             forcing=dict(alpha=0.66, omega=1.3))


@pytest.mark.parametrize("changes, name", [
    (dict(grid=0), "grid"),
    (dict(grid=dict(grid=4, theta_range=(-2.0, 2.0))), "theta_range"),
    (dict(grid=dict(grid=4, theta_range=(1.0, -1.0))), "theta_range"),
    (dict(integration=dict(periods=0)), "periods"),
    (dict(classification=dict(tol=2.0)), "tol"),
    (dict(execution=dict(threads=0)), "threads"),
    (dict(forcing=dict(alpha=0.66, omega=1.3, r0=0.3, s0=0.3)), "unit circle"),
], ids=["grid", "theta_range-wide", "theta_range-reversed", "periods", "tol", "threads",
        "r0-s0"])
def test_basin_bad_input(changes, name):
    kw = {**BASIN, **changes}
    with pytest.raises(ValueError, match=name):
        grid = Lattice(**kw["grid"]) if isinstance(kw["grid"], dict) else kw["grid"]
        rockjit.basin(Block(1), Harmonic(**kw["forcing"]), grid,
                      integration=Integration(**kw["integration"]),
                      classification=Classification(**kw["classification"]),
                      execution=Execution(**kw["execution"]))


SWEEP_INTEGRATION = Integration(periods=2)


@pytest.mark.parametrize("call, name", [
    (lambda: rockjit.sweep(Block(1), Harmonic(omega=1.3), [-0.1],
                           integration=SWEEP_INTEGRATION), "alphas"),
    (lambda: rockjit.sweep(Block(1), Harmonic(omega=1.3), [math.nan],
                           integration=SWEEP_INTEGRATION), "alphas"),
    (lambda: rockjit.alpha_grid((0.5, 0.4), 0.001), "alpha_range"),
    (lambda: rockjit.alpha_grid((0.5, 0.6), 0), "alpha_step"),
    (lambda: rockjit.sweep(Block(1), Harmonic(omega=1.3), [0.6], (0.1, 0.0, 0.0),
                           integration=SWEEP_INTEGRATION), "state"),  # was z0 of 3 numbers
], ids=["alphas-negative", "alphas-nan", "alpha_range", "alpha_step", "state"])
def test_sweep_bad_input(call, name):
    with pytest.raises(ValueError, match=name):
        call()


def test_alpha_grid_includes_end():
    a = rockjit.alpha_grid((0.5, 1.0), 0.001)
    assert a.size == 501 and a[0] == 0.5 and a[-1] == pytest.approx(1.0)


def test_a_sweep_past_overturning_keeps_the_label_and_the_motion():
    # the study's Mao hb=1 diagram plotted the motion after the fall
    run = (Block(1.0, "mao"), Harmonic(omega=1.3), rockjit.alpha_grid((0.50, 0.62), 0.03))
    phys = rockjit.sweep(*run, integration=Integration(periods=200))
    pub = rockjit.sweep(*run, integration=Integration(periods=200, stop_at_overturn=False))
    np.testing.assert_array_equal(pub.label, phys.label)  # the same labels, overturn kept
    fell = np.isfinite(pub.t_overturn)
    assert fell.any() and not fell.all()
    over = BEHAVIOURS.index("overturn")
    assert np.all(phys.label[fell] == over) and np.all(np.isnan(phys.strobe[fell]))
    # ... but the study's way has points and exponents after the fall, of a bounded motion
    assert np.all(np.isfinite(pub.strobe[fell, 0])) and np.all(np.isfinite(pub.lambda_max[fell]))
    assert np.all(pub.motion[fell] != over)
    # where the block never fell, both agree to the bit
    np.testing.assert_array_equal(pub.strobe[~fell], phys.strobe[~fell])
