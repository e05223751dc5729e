"""Grids with several cells per thread in lockstep: the same outputs, bit for bit.

The reference is the single-lane grid kernel (``lanes=1``, :func:`rockjit._engine.kernel._grid`,
which runs every cell through :func:`rockjit._engine.integrate._loop`): the lanes' vector step
must equal the single-lane step in every lane, and every output array of a grid (labels, periods,
end times, overturning instants, stroboscopic samples, impact sections, attractor ids) must be
equal, on the study's four basins, full length and early-stopped, a sweep with per-cell
parameters, a parameter plane (each cell its own step length) and the study's
continue-past-overturning rule, for every lane count and thread count. Grids with tangent
vectors never enter the lanes.
"""

import dataclasses
import math

import numba
import numpy as np
import pytest

import rockjit
from rockjit import Block, Classification, Execution, Harmonic, Integration
from rockjit._engine import integrate as ig
from rockjit._engine import kernel as kn
from rockjit._engine import lanes as ln
from rockjit.grids import plan as gp
from rockjit.result import REST

#: The study's four basins (docs/theory/study.md).
BASINS = (
    dict(hb=1.0, alpha=0.66, omega=1.3, law="housner"),
    dict(hb=1.0, alpha=0.66, omega=1.3, law="mao"),
    dict(hb=2.0, alpha=0.2, omega=1.6, law="housner"),
    dict(hb=2.0, alpha=0.2, omega=1.6, law="mao"),
)
OUTPUTS = ("res", "pts", "imp", "n_got", "n_imp_got")


def basin_plan(hb, alpha, omega, law, *, grid, early_stop=True, **integration):
    """The plan of a basin (``integration``: the keywords of its :class:`rockjit.Integration`)."""
    return rockjit.basin.plan(Block(hb, law), Harmonic(alpha=alpha, omega=omega), grid,
                              integration=Integration(**integration),
                              classification=Classification(early_stop=early_stop))


def chunk(plan, lanes, threads=None):
    return kn.run_chunk(plan.tangent, plan.y0s, plan.pars, plan.ipar, plan.cpar, plan.n_pts,
                        plan.n_imp_pts, threads, lanes)


def assert_same(a, b):
    for k in OUTPUTS:
        assert a[k].shape == b[k].shape, k
        assert np.array_equal(a[k], b[k], equal_nan=True), k


@pytest.mark.parametrize("early_stop", [True, False])
@pytest.mark.parametrize("kw", BASINS, ids=lambda kw: f"hb{kw['hb']:g}-{kw['law']}")
def test_study_basins_bit_for_bit(kw, early_stop):
    plan = basin_plan(**kw, grid=12, periods=40, window=20, early_stop=early_stop)
    ref = chunk(plan, 1)
    assert len(np.unique(ref["res"][:, kn.R_LABEL])) >= 2  # the grid is not trivial
    assert_same(ref, chunk(plan, 8))


def test_lane_counts_and_threads():
    plan = basin_plan(**BASINS[0], grid=10, periods=30, window=15, early_stop=False)
    ref = chunk(plan, 1, threads=1)
    for lanes in (2, 3, 4, 8):
        assert_same(ref, chunk(plan, lanes, threads=1))
    if numba.config.NUMBA_NUM_THREADS >= 2:
        assert_same(ref, chunk(plan, 8, threads=2))


def test_public_results_equal():
    plan = basin_plan(**BASINS[2], grid=10, periods=40, window=20)
    a = gp.run(plan, Execution(lanes=1))
    b = gp.run(plan)  # the default: lanes
    assert Execution().lanes is None and kn.DEFAULT_LANES > 1
    for k in ("label", "period", "t_end", "attractor"):
        assert np.array_equal(getattr(a, k), getattr(b, k), equal_nan=True), k


def test_sweep_and_plane_per_cell_parameters():
    # a sweep: each cell its own forcing amplitude (its own forcing table), impact sections
    sw = rockjit.sweep.plan(Block(1.0, "housner"), Harmonic(omega=1.3),
                            rockjit.alpha_grid((0.5, 1.0), 0.02),
                            integration=Integration(periods=40, window=20), lyapunov=False)
    assert sw.n_imp_pts > 0
    assert_same(chunk(sw, 1), chunk(sw, 8))
    # a plane: each cell its own period, so its own step length and step table
    pl = rockjit.plane.plan(Block(1.0), (0.4, 1.0), (1.0, 2.0), grid=(5, 5),
                            integration=Integration(periods=30, window=15), lyapunov=False)
    assert len(np.unique(pl.pars[:, ig.P_H])) > 1
    assert_same(chunk(pl, 1), chunk(pl, 8))


def test_rest_phases_held_without_scalar_steps():
    # hb=1 Housner just above the uplift threshold (alpha omega^2 = 1.03 cot(thc)): every cell
    # that survives spends most of each period at rest; the lanes hold a resting lane to the
    # grid point while its uplift lies beyond it (one uplift instant per rest phase), and hand
    # it to the single-lane code only for the step that lifts it. The outputs stay one lane's.
    plan = basin_plan(1.0, 0.61, 1.3, "housner", grid=10, periods=30, window=15,
                      early_stop=False)
    ref = chunk(plan, 1)
    out, counts = kn.run_chunk_counted(plan.tangent, plan.y0s, plan.pars, plan.ipar,
                                       plan.cpar, plan.n_pts, plan.n_imp_pts, None, 8)
    assert_same(ref, out)
    assert (ref["res"][:, kn.R_LABEL] != REST).any()  # not every cell rests for good
    steps = counts[:, 0].sum() + counts[:, 1].sum()
    assert counts[:, 1].sum() < 0.1 * steps  # the scalar steps: events and uplifts only


def test_lanes_keep_their_tables_only_for_the_same_forcing():
    # a lane keeps its forcing table for its next cell when alpha omega^2, omega, phi, h and N
    # are the same; cells alternating between two amplitudes must each get their own
    base = basin_plan(1.0, 0.66, 1.3, "housner", grid=8, periods=30, window=15,
                      early_stop=False)
    other = basin_plan(1.0, 0.8, 1.3, "housner", grid=8, periods=30, window=15,
                       early_stop=False)
    plan = dataclasses.replace(base, y0s=base.y0s.copy(), pars=base.pars.copy())
    plan.pars[1::2] = other.pars[1::2]
    assert_same(chunk(plan, 1), chunk(plan, 8))


def test_continue_past_overturning():
    plan = basin_plan(**BASINS[0], grid=8, periods=30, window=15, early_stop=False,
                      stop_at_overturn=False)
    ref = chunk(plan, 1)
    assert np.isfinite(ref["res"][:, kn.R_TOVER]).any()  # some cells fell and went on
    assert_same(ref, chunk(plan, 8))


def test_tangent_grids_stay_single_lane(monkeypatch):
    """The lanes carry no tangent vectors: a grid with exponents asked to run in 8 lanes runs
    one cell at a time, never entering the lanes' kernel, with the results of lanes=1."""
    sw = rockjit.sweep.plan(Block(1.0, "housner"), Harmonic(omega=1.3),
                            rockjit.alpha_grid((0.6, 0.7), 0.05),
                            integration=Integration(periods=20, window=10), lyapunov=True)
    assert sw.tangent
    ref = chunk(sw, 1)
    one = gp.run(sw, Execution(lanes=1))

    def lanes_kernel(*args):
        raise AssertionError("the lanes' kernel ran")

    monkeypatch.setattr(ln, "grid_lanes", lanes_kernel)
    assert_same(ref, chunk(sw, 8))
    eight = gp.run(sw, Execution(lanes=8))
    for k in ("label", "period", "t_end", "lambda_max", "strobe", "impact_section", "attractor"):
        assert np.array_equal(getattr(one, k), getattr(eight, k), equal_nan=True), k
    assert np.all(np.isfinite(eight.lambda_max))  # the exponents were computed
    # the stand-in is live: the same grid without tangent vectors does enter the lanes
    with pytest.raises(AssertionError, match="lanes' kernel ran"):
        chunk(dataclasses.replace(sw, tangent=False), 8)


@pytest.mark.parametrize("bad", [0, 9, 2.5, "four", True])
def test_lanes_out_of_range(bad):
    plan = basin_plan(**BASINS[0], grid=2, periods=2, window=1)
    with pytest.raises(ValueError, match="lanes"):
        chunk(plan, bad)
    with pytest.raises(ValueError, match="lanes"):
        Execution(lanes=bad)


def test_vector_step_equals_single_lane_step():
    """block_step_lanes against integrate.block_step lane by lane, on random states (a few
    outside the polynomials' range, some at rest, some crossing theta = 0)."""
    rng = np.random.default_rng(17)
    W = ln.W
    block = Block(hb=1.0)
    n_per = 64
    p = kn.pack(block, Harmonic(alpha=0.66, omega=1.3), 0.3, Integration(), n_per)
    par = np.zeros(ig.N_PARW)
    par[:ig.N_PAR] = p
    par[ig.P_STHC] = math.sin(p[ig.P_THC])
    par[ig.P_CTHC] = math.cos(p[ig.P_THC])
    tab = np.zeros((ig.N_TAB, ig.N_STAGES + 1))
    ig.step_table(par[ig.P_OMEGA], par[ig.P_H], tab)
    ftl = rng.uniform(-1.0, 1.0, n_per * (ig.N_STAGES + 1) * W)
    lin = np.zeros(ln.N_LIN * W)
    lout = np.zeros(ln.N_LOUT * W)
    n_far = n_fast = 0
    for trial in range(40):
        j = int(rng.integers(n_per))
        x = rng.uniform(-0.6, 0.6, W)
        v = rng.uniform(-3.0, 3.0, W)
        side = rng.choice([-1, 1, 1, 0], W)
        if trial % 5 == 0:
            v[:2] = 12.0  # far from the start within the step
        for l in range(W):
            lin[ln.LI_X * W + l] = x[l]
            lin[ln.LI_V * W + l] = v[l]
            lin[ln.LI_K * W + l] = rng.uniform(-2.0, 2.0)
            lin[ln.LI_S * W + l] = math.sin(x[l])
            lin[ln.LI_C * W + l] = math.cos(x[l])
            lin[ln.LI_SG * W + l] = side[l]
            lin[ln.LI_STHC * W + l] = par[ig.P_STHC]
            lin[ln.LI_CTHC * W + l] = par[ig.P_CTHC]
            lin[ln.LI_XI * W + l] = par[ig.P_XI]
            lin[ln.LI_THOVER * W + l] = par[ig.P_THOVER]
            ln.lane_tables(tab, lin, l)
        before = lin.copy()
        ln.block_step_lanes(W, j, lin, lout, ftl)
        for l in range(W):
            K = np.zeros((ig.N_STAGES + 1, 2))
            K[0, 1] = before[ln.LI_K * W + l]
            trig = np.array([before[ln.LI_S * W + l], before[ln.LI_C * W + l], 0.0, 0.0])
            fr = np.array([ftl[(j * 7 + i) * W + l] for i in range(7)])
            sd = int(side[l])
            xe, ve, far = _block_step(x[l], v[l], fr, tab, sd if sd else 1, par, K, trig)
            if sd == 0:  # the vector computes a corner of 0; only its flag matters
                assert lout[ln.LO_FAST * W + l] == 0.0
                continue
            assert lout[ln.LO_X * W + l] == xe and lout[ln.LO_V * W + l] == ve
            assert lout[ln.LO_FAR * W + l] == far
            assert lout[ln.LO_S * W + l] == trig[2] and lout[ln.LO_C * W + l] == trig[3]
            for i in range(1, 7):
                assert lout[(ln.LO_KV + i) * W + l] == K[i, 0]
                assert lout[(ln.LO_KA + i) * W + l] == K[i, 1]
            # fast: in range and none of detect's events (written out from detect's tests)
            g0, g1 = sd * x[l], sd * xe
            event = g1 >= par[ig.P_THOVER] or g1 < 0.0 or (g0 > 0 and sd * v[l] < 0
                                                           and sd * ve > 0)
            fast = far <= 1.0 and not event
            assert lout[ln.LO_FAST * W + l] == (1.0 if fast else 0.0)
            # a fast lane's state is advanced, any other left as it was
            want = (xe, ve, K[6, 1], trig[2], trig[3]) if fast else \
                tuple(before[r * W + l] for r in (ln.LI_X, ln.LI_V, ln.LI_K, ln.LI_S, ln.LI_C))
            got = tuple(lin[r * W + l] for r in (ln.LI_X, ln.LI_V, ln.LI_K, ln.LI_S, ln.LI_C))
            assert got == want
            n_far += far > 1.0
            n_fast += fast
    assert n_far > 0 and 0 < n_fast < 40 * W  # every branch was seen


@numba.njit(cache=False)
def _block_step(x, v, fr, tab, side, par, K, trig):
    jac = np.zeros(ig.N_STAGES + 1)
    return ig.block_step(True, None, x, v, fr, tab, side, par, K, jac, trig)
