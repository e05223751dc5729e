"""Fragility curves: the lognormal maximum-likelihood fit, and incremental dynamic analysis over
a few records.

Checked: on binomial data drawn from a known lognormal curve, the fit recovers the median and
the dispersion within a few standard errors, and its standard errors (from the observed
information matrix) are calibrated: over 200 data sets, the 95 % intervals hold the truth in
about 95 % of them; data without an interior maximum (all survive, all overturn, a clean cut)
are reported, not fitted; the closed form from collapse capacities. The analysis itself on
three short records x a few intensities x two laws x two sizes: the shapes, the scaling to each
intensity (PGA and PGV), no motion below the uplift intensity, the fits and the summary, the
larger block the safer, and a record's analysis equal to its single runs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import ndtr

import rockjit
from rockjit import Block, Record, Transient
from rockjit.ground import fit_capacities, fit_lognormal
from rockjit.ground.methods import transient_scipy
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
    from rockjit.ground.fitting import _nll
    best = _nll(math.log(f.median), f.beta, np.log(X), k, n)
    for dm, db in ((0.01, 0), (-0.01, 0), (0, 0.01), (0, -0.01)):
        assert _nll(math.log(f.median) + dm, f.beta + db, np.log(X), k, n) > best
    np.testing.assert_allclose(f.probability([f.median]), [0.5])


def test_fit_standard_errors_are_calibrated():
    rng = np.random.default_rng(20240610)
    hits = np.zeros(2)
    n_sets = 200
    for _ in range(n_sets):
        k, n = _draw(rng)
        f = fit_lognormal(X, k, n)
        hits += [abs(f.median - MEDIAN) < 1.96 * f.se_median,
                 abs(f.beta - BETA) < 1.96 * f.se_beta]
    # 95 % nominal; a binomial(200, 0.95) lies in [181, 197] with probability > 0.99
    assert np.all(hits >= 181) and np.all(hits <= 197), hits


def test_data_without_an_interior_maximum():
    x = [1.0, 2.0, 3.0]
    none = fit_lognormal(x, [0, 0, 0], [5, 5, 5])
    assert none.status == "all_survive" and none.bound == 3.0 and math.isnan(none.median)
    every = fit_lognormal(x, [5, 5, 5], [5, 5, 5])
    assert every.status == "all_overturn" and every.bound == 1.0 and math.isnan(every.beta)
    cut = fit_lognormal(x, [0, 5, 5], [5, 5, 5])
    assert cut.status == "separated" and cut.beta == 0.0
    assert cut.median == pytest.approx(math.sqrt(2.0))
    np.testing.assert_array_equal(cut.probability([1.2, 1.5]), [0.0, 1.0])
    assert fit_lognormal(x, [0, 0, 0], [0, 0, 0]).status == "no_data"
    assert np.all(np.isnan(none.probability([1.0, 2.0])))
    with pytest.raises(ValueError, match="overturned counts"):
        fit_lognormal(x, [0, 6, 5], [5, 5, 5])
    with pytest.raises(ValueError, match="positive"):
        fit_lognormal([0.0, 1.0], [0, 1], [1, 1])


def test_fit_from_capacities():
    rng = np.random.default_rng(4)
    c = np.exp(rng.normal(math.log(MEDIAN), BETA, 400))
    f = fit_capacities(np.r_[c, np.inf, np.nan])
    assert f.status == "ok" and f.n_runs == 402 and f.n_overturned == 400
    assert f.median == pytest.approx(math.exp(np.mean(np.log(c))))
    assert f.beta == pytest.approx(np.std(np.log(c)))
    assert abs(f.median - MEDIAN) < 3 * f.se_median and abs(f.beta - BETA) < 3 * f.se_beta


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
            assert d["overturn"]["status"] in ("ok", "separated", "all_survive",
                                               "all_overturn")
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
