"""Fragility curves: the lognormal maximum-likelihood fit, and incremental dynamic analysis over
a few records.

Checked: on binomial data drawn from a known lognormal curve, the fit is the likelihood's
maximum (against the test's own likelihood on a grid), its profile-likelihood intervals end
where a brute-force profile drops by chi2_1(0.95)/2, and by Monte-Carlo over 200 data sets the
intervals hold the truth at about the nominal rate and the standard errors match the spread of
the estimates; data that do not identify a fit (all survive, all overturn, one intensity level,
complete and quasi-complete separation, a flat likelihood) get their status and no estimate;
the closed form from collapse capacities, its standard errors and exact intervals by
Monte-Carlo; a record that overturns at the lowest intensity has its capacity below the list,
against a loop over the outcomes. The analysis itself on
three short records x a few intensities x two laws x two sizes: the shapes, the scaling to each
intensity (PGA and PGV), no motion below the uplift intensity, the fits and the summary, the
larger block the safer, and a record's analysis equal to its single runs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar
from scipy.special import ndtr
from scipy.stats import binom, chi2, norm

import rockjit
from rockjit import Block, Record, Transient
from rockjit.ground import fit_capacities, fit_lognormal
from rockjit.ground.batch import transient_scipy
from rockjit.ground.response import SAFE, UNRESOLVED

MEDIAN, BETA = 2.0, 0.35
X = np.linspace(0.8, 4.0, 12)


def _draw(rng, runs=40):
    n = np.full(X.size, runs)
    return rng.binomial(n, ndtr(np.log(X / MEDIAN) / BETA)), n


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fit_recovers_a_known_lognormal(seed):
    k, n = _draw(np.random.default_rng(seed))
    f = fit_lognormal(X, k, n)
    assert f.status == "ok" and f.n_runs == n.sum() and f.n_overturned == k.sum()
    assert abs(f.median - MEDIAN) < 3 * f.se_median
    assert abs(f.beta - BETA) < 3 * f.se_beta
    assert 0 < f.se_median < 0.2 and 0 < f.se_beta < 0.1
    assert f.se_median == pytest.approx(f.median * f.se_log_median)
    # the maximum: no nearby curve is more likely
    best = _loglik(math.log(f.median), f.beta, X, k, n)
    for dm, db in ((0.01, 0), (-0.01, 0), (0, 0.01), (0, -0.01)):
        assert _loglik(math.log(f.median) + dm, f.beta + db, X, k, n) < best
    np.testing.assert_allclose(f.probability([f.median]), [0.5])


def _loglik(mu, beta, x, k, n):
    """The binomial log-likelihood, written out with scipy.stats (the test's own); ``mu`` and
    ``beta`` may be arrays of the same shape (one value each)."""
    mu, beta = np.asarray(mu, float)[..., None], np.asarray(beta, float)[..., None]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.sum(binom.logpmf(k, n, norm.cdf((np.log(x) - mu) / beta)), axis=-1)


def _profile(x, k, n, *, beta=None, mu=None):
    """The profile log-likelihood at a fixed ``beta`` (maximised over ``mu``) or at a fixed
    ``mu`` (over ``ln beta``), by brute force: the best of a fine grid over a wide bracket, then
    a bounded scalar minimisation between its neighbours."""
    if beta is not None:
        fun = lambda m: _loglik(m, np.full_like(m, beta), x, k, n)     # noqa: E731
        grid = np.linspace(-30.0, 30.0, 12001)
    else:
        fun = lambda lb: _loglik(np.full_like(lb, mu), np.exp(lb), x, k, n)  # noqa: E731
        grid = np.linspace(-12.0, 6.0, 3601)
    v = fun(grid)
    i = int(np.argmax(v))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    with np.errstate(invalid="ignore"):     # -inf where a probability is 0 or 1
        r = minimize_scalar(lambda t: -float(fun(np.array(t))), bounds=(lo, hi),
                            method="bounded", options=dict(xatol=1e-12))
    return max(-r.fun, float(v[i]))


def test_fit_is_the_maximum_and_its_intervals_are_the_profile_likelihoods():
    k, n = _draw(np.random.default_rng(7))
    f = fit_lognormal(X, k, n)
    best = _loglik(math.log(f.median), f.beta, X, k, n)
    # the maximum: no point of a grid around it is more likely
    for dm in np.linspace(-0.05, 0.05, 11):
        for db in np.linspace(-0.05, 0.05, 11):
            assert _loglik(math.log(f.median) + dm, f.beta + db, X, k, n) <= best + 1e-9
    # each end of each interval: the profile lies chi2_1(0.95) / 2 = 1.9207 below the maximum
    half = chi2.ppf(0.95, 1) / 2
    assert f.confidence == 0.95
    for b in f.beta_ci:
        assert best - _profile(X, k, n, beta=b) == pytest.approx(half, abs=1e-5)
    for m in f.median_ci:
        assert best - _profile(X, k, n, mu=math.log(m)) == pytest.approx(half, abs=1e-5)
    assert f.median_ci[0] < f.median < f.median_ci[1] and f.beta_ci[0] < f.beta < f.beta_ci[1]


def test_fit_intervals_and_standard_errors_are_calibrated():
    """Monte-Carlo over 200 data sets drawn from the known curve: the profile-likelihood
    intervals and the standard errors' 95 % intervals hold the truth at about the nominal rate,
    and the standard errors match the spread of the estimates themselves."""
    rng = np.random.default_rng(20240610)
    n_sets = 200
    hits = np.zeros(4)
    est, se = [], []
    for _ in range(n_sets):
        k, n = _draw(rng)
        f = fit_lognormal(X, k, n)
        assert f.status == "ok"
        hits += [f.median_ci[0] < MEDIAN < f.median_ci[1], f.beta_ci[0] < BETA < f.beta_ci[1],
                 abs(f.median - MEDIAN) < 1.96 * f.se_median,
                 abs(f.beta - BETA) < 1.96 * f.se_beta]
        est.append([math.log(f.median), f.beta])
        se.append([f.se_median / f.median, f.se_beta])     # se(ln median) by the delta method
    # 95 % nominal; a binomial(200, 0.95) lies in [181, 197] with probability > 0.99
    assert np.all(hits >= 181) and np.all(hits <= 197), hits
    # the spread of 200 estimates is known to about 5 %: a standard error 20 % off fails
    ratio = np.sqrt(np.mean(np.square(se), axis=0)) / np.std(est, axis=0)
    assert np.all(ratio > 0.8) and np.all(ratio < 1.2), ratio


def test_data_without_an_interior_maximum():
    x = [1.0, 2.0, 3.0]
    none = fit_lognormal(x, [0, 0, 0], [5, 5, 5])
    assert none.status == "all_survive" and none.bound == 3.0 and math.isnan(none.median)
    every = fit_lognormal(x, [5, 5, 5], [5, 5, 5])
    assert every.status == "all_overturn" and every.bound == 1.0 and math.isnan(every.beta)
    assert fit_lognormal(x, [0, 0, 0], [0, 0, 0]).status == "no_data"
    assert np.all(np.isnan(none.probability([1.0, 2.0])))
    with pytest.raises(ValueError, match="overturned counts"):
        fit_lognormal(x, [0, 6, 5], [5, 5, 5])
    with pytest.raises(ValueError, match="positive"):
        fit_lognormal([0.0, 1.0], [0, 1], [1, 1])
    with pytest.raises(ValueError, match="confidence must be in"):
        fit_lognormal(x, [0, 1, 5], [5, 5, 5], confidence=1.0)


def _unidentified(f, reason):
    assert f.status == "unidentified" and reason in f.reason, f
    assert math.isnan(f.median) and math.isnan(f.beta)
    assert math.isnan(f.se_median) and math.isnan(f.se_beta)
    assert np.all(np.isnan(f.probability([1.0, 3.0])))
    d = f.to_dict()
    assert d["status"] == "unidentified" and math.isnan(d["median"]) and d["reason"]


def test_one_intensity_level_is_unidentified():
    # two records at one level, one overturning: the likelihood is flat in beta (each beta
    # fits with its own median), so the maximum says nothing about beta
    x, k, n = np.array([3.0]), np.array([1]), np.array([2])
    flat = [_profile(x, k, n, beta=b) for b in (0.05, 0.3, 1.0, 5.0)]
    np.testing.assert_allclose(flat, binom.logpmf(1, 2, 0.5), rtol=1e-8)
    f = fit_lognormal(x, k, n)
    _unidentified(f, "one intensity level")
    assert f.beta_ci == (0.0, math.inf) and f.median_ci == (0.0, math.inf)


def test_quasi_complete_separation_is_unidentified():
    # two records whose capacities are 3.0 and 3.25, on the default intensities 1.25 to 6:
    # both survive below 3, one overturns at 3, both from 3.25 on
    x = np.round(np.arange(1.25, 6.001, 0.25), 10)
    k = np.where(x < 3.0, 0, np.where(x == 3.0, 1, 2))
    n = np.full(x.size, 2)
    # the likelihood only grows as beta -> 0 (the median at 3): no interior maximum
    sup = _loglik(math.log(3.0), 1e-4, x, k, n)
    assert sup == pytest.approx(binom.logpmf(1, 2, 0.5), rel=1e-9)
    assert all(_profile(x, k, n, beta=b) < sup for b in (0.01, 0.05, 0.2))
    f = fit_lognormal(x, k, n)
    _unidentified(f, "quasi-complete separation at 3")
    # what the data do bound: beta below the upper end, the median around 3
    half = chi2.ppf(0.95, 1) / 2
    assert f.beta_ci[0] == 0.0
    assert sup - _profile(x, k, n, beta=f.beta_ci[1]) == pytest.approx(half, abs=1e-5)
    assert f.median_ci[0] < 3.0 < f.median_ci[1]


def test_complete_separation_is_unidentified():
    f = fit_lognormal([1.0, 2.0, 3.0], [0, 5, 5], [5, 5, 5])
    _unidentified(f, "complete separation between 1 and 2")
    assert f.beta_ci[0] == 0.0 and 1.0 <= f.median_ci[0] + 1e-6 and f.median_ci[1] <= 2.0 + 1e-6


@pytest.mark.parametrize("k", [[1, 2, 1], [1, 1, 2], [2, 1, 0]])
def test_a_flat_likelihood_is_unidentified(k):
    # the fraction does not rise clearly with the intensity: a constant probability is not
    # rejected by the likelihood-ratio test, so beta has no upper end
    x, n = np.array([1.0, 2.0, 3.0]), np.array([4, 4, 4])
    k = np.array(k)
    p = k.sum() / n.sum()
    flat = float(np.sum(binom.logpmf(k, n, p)))
    best = max(_profile(x, k, n, beta=b) for b in np.geomspace(0.05, 100, 30))
    assert 2 * (best - flat) < chi2.ppf(0.95, 1)
    f = fit_lognormal(x, k, n)
    assert f.status == "unidentified" and math.isnan(f.median) and math.isnan(f.beta)
    if math.isfinite(f.beta_ci[0]):
        assert f.beta_ci[1] == math.inf


def test_fit_on_random_designs_is_an_estimate_or_says_why():
    """Random designs (1 to 12 levels, 1 to 500 runs each, curves steep and flat): every fit
    either is "ok", with finite intervals around its estimate at which the test's own profile
    likelihood has dropped by chi2_1(0.95)/2, or carries no estimate and a reason."""
    rng = np.random.default_rng(2026)
    half = chi2.ppf(0.95, 1) / 2
    seen = set()
    for _ in range(80):
        levels = int(rng.integers(1, 13))
        x = np.sort(rng.choice(np.geomspace(0.05, 50.0, 60), levels, replace=False))
        n = rng.integers(1, int(rng.choice([3, 40, 500])), levels)
        k = rng.binomial(n, ndtr(np.log(x / math.exp(rng.uniform(-2, 3))) /
                                 math.exp(rng.uniform(-3, 1))))
        f = fit_lognormal(x, k, n)
        seen.add(f.status)
        if f.status == "ok":
            assert f.median_ci[0] < f.median < f.median_ci[1] < math.inf
            assert 0 < f.beta_ci[0] < f.beta < f.beta_ci[1] < math.inf
            best = _loglik(math.log(f.median), f.beta, x, k, n)
            drop = best - _profile(x, k, n, beta=f.beta_ci[1])
            assert drop == pytest.approx(half, abs=1e-4)
        else:
            assert math.isnan(f.median) and math.isnan(f.beta)
            assert f.status != "unidentified" or f.reason
    assert seen >= {"ok", "unidentified", "all_survive", "all_overturn"}


def test_fit_from_capacities():
    rng = np.random.default_rng(4)
    c = np.exp(rng.normal(math.log(MEDIAN), BETA, 400))
    f = fit_capacities(np.r_[c, np.inf, np.nan])
    assert f.status == "ok" and f.n_runs == 402 and f.n_overturned == 400
    assert f.median == pytest.approx(math.exp(np.mean(np.log(c))))
    assert f.beta == pytest.approx(np.std(np.log(c)))
    assert abs(f.median - MEDIAN) < 3 * f.se_median and abs(f.beta - BETA) < 3 * f.se_beta
    same = fit_capacities([4.0, 4.0, np.inf])
    assert same.status == "unidentified" and math.isnan(same.beta) and "every capacity" in \
        same.reason
    assert fit_capacities([4.0, np.nan]).status == "no_data"


def test_capacity_fit_standard_errors_and_intervals_by_monte_carlo():
    rng = np.random.default_rng(31)
    # the standard errors: 2000 sets of 50 capacities; the spread of the estimates is known to
    # about 2 %, so a standard error 10 % off fails (beta / sqrt(n) for beta's is 41 % off)
    fits = [fit_capacities(np.exp(rng.normal(math.log(MEDIAN), BETA, 50))) for _ in range(2000)]
    est = np.array([[math.log(f.median), f.beta] for f in fits])
    se = np.array([[f.se_log_median, f.se_beta] for f in fits])
    ratio = np.sqrt(np.mean(se ** 2, axis=0)) / np.std(est, axis=0)
    np.testing.assert_allclose(ratio, 1.0, atol=0.1)
    # the intervals are exact: 1000 sets of 8 capacities; a binomial(1000, 0.95) lies in
    # [927, 972] with probability > 0.999
    hits = np.zeros(2)
    for _ in range(1000):
        f = fit_capacities(np.exp(rng.normal(math.log(MEDIAN), BETA, 8)))
        hits += [f.median_ci[0] < MEDIAN < f.median_ci[1], f.beta_ci[0] < BETA < f.beta_ci[1]]
    assert np.all(hits >= 927) and np.all(hits <= 972), hits


# ---- incremental dynamic analysis -----------------------------------------------------------

def _records():
    """Three short synthetic records (6 s at 100 Hz): a pulse-like one and two broadband ones."""
    dt = 0.01
    t = np.arange(601) * dt
    env = np.sin(np.pi * t / t[-1]) ** 2
    rng = np.random.default_rng(11)
    out = [Record(0.3 * np.sin(2 * np.pi * 0.8 * t) * env, dt, name="pulse-like")]
    for k in range(2):
        a = sum(rng.normal(0, 0.1) * np.sin(2 * np.pi * f * t + rng.uniform(0, 6))
                for f in (0.5, 1.1, 2.3, 3.7, 5.3))
        out.append(Record(a * env, dt, name=f"broadband {k}"))
    return out


@pytest.fixture(scope="module")
def ida():
    return rockjit.fragility(Block(hb=3), _records(), [0.4, 4.0], [0.8, 1.5, 3.0, 6.0],
                             laws=("housner", "mao"), integration=Transient(free_time=30.0))


def test_ida_shapes_and_scaling(ida):
    assert ida.outcome.shape == (2, 2, 3, 4) and ida.max_rotation.shape == (2, 2, 3, 4)
    assert ida.laws == ("housner", "mao") and list(ida.sizes) == [0.4, 4.0]
    assert not np.any(ida.outcome == UNRESOLVED)
    for r, rec in enumerate(ida.records):
        for j, x in enumerate(ida.intensity):
            assert rec.scaled(ida.scale[r, j]).pga * 3.0 == pytest.approx(x, rel=1e-12)
    # below the uplift intensity (PGA < g tan alpha) nothing moves
    assert np.all(ida.outcome[..., 0] == SAFE) and np.all(ida.max_rotation[..., 0] == 0.0)


def test_ida_fits_and_summary(ida):
    s = ida.summary()
    assert set(s["laws"]) == {"housner", "mao"} and s["sizes"] == [0.4, 4.0]
    assert len(s["records"]) == 3 and s["measure"] == "pga"
    for law in ida.laws:
        for size in ("0.4", "4"):
            d = s["laws"][law]["sizes"][size]
            assert set(d) >= {"overturn", "exceed_0.5", "exceed_1", "capacity",
                              "fraction_overturned"}
            assert len(d["fraction_overturned"]) == 4
            for name in ("overturn", "exceed_0.5", "exceed_1", "capacity"):
                fit = d[name]
                assert fit["status"] in ("ok", "unidentified", "all_survive", "all_overturn",
                                         "no_data")
                assert len(fit["median_ci"]) == 2 and len(fit["beta_ci"]) == 2
                if fit["status"] == "ok":
                    assert fit["median_ci"][0] < fit["median"] < fit["median_ci"][1]
                    assert fit["beta_ci"][0] < fit["beta"] < fit["beta_ci"][1]
                else:   # no estimate presented
                    assert math.isnan(fit["median"]) and math.isnan(fit["beta"])
                if fit["status"] == "unidentified":
                    assert fit["reason"]
            # exceeding a rotation is at least as likely as overturning
            assert np.all(np.array(d["fraction_exceed_1"]) >=
                          np.array(d["fraction_overturned"]))
            assert np.all(np.array(d["fraction_exceed_0.5"]) >=
                          np.array(d["fraction_exceed_1"]))
    assert "mao_over_housner_median" in s and "size_effect" in s
    assert ida.arrays()["outcome"].shape == (2, 2, 3, 4)


def test_the_larger_block_is_the_safer(ida):
    small, large = ida.fraction("overturn")[:, 0], ida.fraction("overturn")[:, 1]
    assert np.all(large <= small) and small.sum() > large.sum()
    # where neither block fell, the larger one swung less
    both = ~ida.overturned[:, 0] & ~ida.overturned[:, 1]
    assert both.any()
    assert np.all(ida.max_rotation[:, 1][both] <= ida.max_rotation[:, 0][both] + 1e-12)


@pytest.mark.parametrize("j", [1, 2])  # one that rocks and survives, one that overturns
def test_ida_cell_is_the_single_run(ida, j):
    # the analysis runs compiled, the single run on the scipy path
    rec = ida.records[1]
    r = rockjit.simulate(Block(hb=3, law="mao"), rec.bind(size=0.4).scaled(ida.scale[1, j]),
                         method=transient_scipy(),
                         integration=Transient(free_time=30.0, stop_when_decided=True))
    assert r.outcome == ida.outcome[1, 0, 1, j]
    assert r.max_rotation == pytest.approx(ida.max_rotation[1, 0, 1, j], abs=1e-9)
    if j == 1:
        assert 0.01 < r.max_rotation < 1.0  # it moved, and stayed up


def test_ida_by_pgv():
    recs = _records()[:2]
    fr = rockjit.fragility(Block(hb=2, law="mao"), recs, [1.0], [0.05, 0.4], measure="pgv",
                           integration=Transient(free_time=10.0))
    for r, rec in enumerate(recs):
        for j, x in enumerate(fr.intensity):
            assert rec.scaled(fr.scale[r, j]).pgv == pytest.approx(x, rel=1e-12)
    assert fr.summary()["measure"] == "pgv"


def test_fragility_refusals():
    recs = _records()[:1]
    b = Block(hb=2)
    with pytest.raises(ValueError, match="size must be in"):
        rockjit.fragility(b, recs, [0.0], [1.0])
    with pytest.raises(ValueError, match="intensities must be increasing"):
        rockjit.fragility(b, recs, [1.0], [2.0, 1.0])
    with pytest.raises(ValueError, match="intensity must be in"):
        rockjit.fragility(b, recs, [1.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="measure"):
        rockjit.fragility(b, recs, [1.0], [1.0], measure="sa")
    with pytest.raises(ValueError, match="law"):
        rockjit.fragility(b, recs, [1.0], [1.0], laws=("housner", "other"))
    with pytest.raises(ValueError, match="no motion"):
        rockjit.fragility(b, [Record(np.zeros(5), 0.01)], [1.0], [1.0])
    with pytest.raises(ValueError, match="rockjit.Record"):
        rockjit.fragility(b, [np.zeros(5)], [1.0], [1.0])
    with pytest.raises(ValueError, match="method must be"):
        rockjit.fragility(b, recs, [1.0], [1.0], method="compiled")
    with pytest.raises(ValueError, match="sizes must be distinct"):
        rockjit.fragility(b, recs, [1.0, 1.0], [1.0])


def _capacities_by_loop(intensity, overturned):
    """Each record's capacity by a plain loop: ``"below"`` where the lowest intensity already
    overturned it, ``inf`` where none did, else the first intensity that did."""
    out = []
    for row in overturned:
        first = next((j for j, o in enumerate(row) if o), None)
        out.append(math.inf if first is None else "below" if first == 0 else intensity[first])
    return out


def test_capacity_below_the_list():
    from rockjit.ground.fragility import FragilityResult
    from rockjit.ground.response import OVERTURN_IMPACT, OVERTURN_NO_IMPACT
    x = np.array([1.5, 2.0, 3.0, 4.0])
    o = np.full((1, 1, 5, 4), SAFE, dtype=np.int8)
    o[0, 0, 0, :] = OVERTURN_IMPACT                   # overturns at every level
    o[0, 0, 1, 2:] = OVERTURN_NO_IMPACT               # first at 3.0
    o[0, 0, 2, 0] = OVERTURN_IMPACT                   # at the lowest only, then survives
    o[0, 0, 3, [1, 3]] = OVERTURN_IMPACT              # first at 2.0
    # record 4 never overturns
    fr = FragilityResult(block=Block(hb=3), laws=("housner",), sizes=np.array([1.0]),
                         records=(), intensity=x, measure="pga", outcome=o,
                         max_rotation=np.zeros(o.shape), t_overturn=np.zeros(o.shape),
                         scale=np.ones((5, 4)))
    got = fr.capacities("housner", 1.0)
    want = _capacities_by_loop(x, fr.overturned[0, 0])
    assert want == ["below", 3.0, "below", 2.0, math.inf]
    for g, w in zip(got, want):
        assert math.isnan(g) if w == "below" else g == w
    # the capacity fit uses the records whose capacity lies in the list
    f = fit_capacities(got)
    assert f.n_runs == 5 and f.n_overturned == 2
    assert f.median == pytest.approx(math.sqrt(6.0))


def test_ida_capacities_match_a_loop(ida):
    for li, law in enumerate(ida.laws):
        for si, size in enumerate(ida.sizes):
            got = ida.capacities(law, float(size))
            want = _capacities_by_loop(ida.intensity, ida.overturned[li, si])
            for g, w in zip(got, want):
                assert math.isnan(g) if w == "below" else g == w


@pytest.mark.parametrize("levels, curves", [(([1, 3], [2, 3]), 1), (([2, 3], [3]), 0)])
def test_the_figure_draws_a_curve_only_for_an_identified_fit(levels, curves):
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib import pyplot as plt
    from rockjit.ground.figures import fig_fragility
    from rockjit.ground.fragility import FragilityResult
    from rockjit.ground.response import OVERTURN_IMPACT
    # two records at four intensities, each overturning the block at the levels given (0 is
    # 1.5): in the first pair record 0 survives at 3.0 above its overturning at 2.0 (the data
    # overlap: a fit); the second pair is quasi-separated at 3.0 (no fit)
    x = np.array([1.5, 2.0, 3.0, 4.0])
    o = np.full((1, 1, 2, 4), SAFE, dtype=np.int8)
    for r, js in enumerate(levels):
        o[0, 0, r, js] = OVERTURN_IMPACT
    fr = FragilityResult(block=Block(hb=3), laws=("housner",), sizes=np.array([1.0]),
                         records=(), intensity=x, measure="pga", outcome=o,
                         max_rotation=np.zeros(o.shape), t_overturn=np.zeros(o.shape),
                         scale=np.ones((2, 4)))
    fit = fit_lognormal(x, fr.overturned[0, 0].sum(axis=0), np.full(4, 2))
    assert fit.status == ("ok" if curves else "unidentified")
    fr.fits = {"housner": {1.0: {"overturn": fit}}}
    fig = fig_fragility(fr)
    try:
        ax = fig.axes[0]
        drawn = [ln for ln in ax.get_lines() if ln.get_linestyle() not in ("None", "", " ")]
        assert len(drawn) == curves
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any(("median" in t) == bool(curves) for t in texts), texts
    finally:
        plt.close(fig)
