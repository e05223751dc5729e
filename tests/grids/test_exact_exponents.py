"""A grid cell's ``lambda_max`` is exact where the cell settled on a periodic orbit.

Checked against:

- the scipy path's monodromy by central finite differences (DOP853 at ``rtol = 1e-12``), on
  the branch of Mao's ``h/b = 1`` diagram at ``omega = 1.3``, ``alpha`` in 0.30-0.50, where
  every cell is a stable symmetric period-1 orbit whose multipliers are a complex pair: there
  ``lambda_max`` equals ``ln|mu1| / T`` to ``1e-6``, and ``lambda1 = lambda2`` is fixed by
  ``det M`` alone (docs/theory/exponents.md, "The monodromy matrix"): the same value at every
  amplitude, which the finite-window estimate (kept as ``lambda_window``) is not;
- the cells that are not periodic (chaotic, aperiodic, rest, overturn) keep the window's
  estimate, bit for bit;
- a plane's cells are each their own system: every periodic cell's exponent is the Floquet
  exponent of its own cycle at its own forcing;
- an orbit that passes through rest has monodromy zero: ``-inf``.
"""

import math

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic, Integration, Scipy
from rockjit.grids.identity import floquet
from rockjit.result import BEHAVIOURS

MAO = Block(hb=1.0, law="mao")
OMEGA = 1.3
PERIODIC = [BEHAVIOURS.index(n) for n in ("symmetric", "asymmetric", "multiperiodic")]


@pytest.fixture(scope="module")
def mao_branch():
    return rockjit.sweep(MAO, Harmonic(omega=OMEGA), rockjit.alpha_grid((0.30, 0.50), 0.02))


def _phase(sw):
    th, dth, r0, s0 = sw.settings["z0"]
    return math.atan2(r0, s0)


def _cycle_point(sw, i):
    got = np.count_nonzero(np.isfinite(sw.strobe[i, :, 0]))
    return sw.strobe[i, got - sw.period[i]]


def _fd_monodromy(block, forcing, x, p, eps=1e-6):
    """Central differences of the scipy path's map over ``p`` periods."""
    def flow(y):
        r = rockjit.simulate(block, forcing, (y[0], y[1]), integration=Integration(periods=p),
                             method=Scipy("DOP853", rtol=1e-12, atol=1e-12))
        return r.state[:2]
    return np.column_stack([(flow(x + d) - flow(x - d)) / (2 * eps)
                            for d in (np.array([eps, 0.0]), np.array([0.0, eps]))])


def test_the_mao_branch_is_one_symmetric_focus(mao_branch):
    sw = mao_branch
    assert sw.alpha.size == 11
    assert all(str(n) == "symmetric" for n in sw.names[sw.label]) and np.all(sw.period == 1)


@pytest.mark.parametrize("i", [0, 3, 6, 9])
def test_lambda_max_is_the_floquet_exponent_of_the_scipy_monodromy(mao_branch, i):
    sw = mao_branch
    T = 2 * math.pi / OMEGA
    forcing = Harmonic(alpha=float(sw.alpha[i]), omega=OMEGA, phase=_phase(sw))
    x = _cycle_point(sw, i)
    # no impact at the sampling instant (there the map at t = kT jumps, and so would the
    # differences; at alpha = 0.50 one nearly is, theta(kT) = 1e-6)
    assert abs(x[0]) > 1e-3
    M = _fd_monodromy(MAO, forcing, x, 1)
    mu = np.linalg.eigvals(M)
    assert abs(mu[0].imag) > 0.05  # a complex pair: the case the window cannot average out
    lam_fd = math.log(max(abs(mu))) / T
    assert sw.lambda_max[i] == pytest.approx(lam_fd, abs=1e-6)
    # a complex pair: lambda1 = lambda2 = ln(det M) / (2T)
    assert sw.lambda_max[i] == pytest.approx(math.log(abs(np.linalg.det(M))) / (2 * T), abs=1e-6)


def test_the_exact_exponent_is_flat_along_the_branch_and_the_window_is_not(mao_branch):
    sw = mao_branch
    # det M = e^(2n) exp(-3/4 xi T) with n = 2 impacts per period, at every amplitude
    T = 2 * math.pi / OMEGA
    e = MAO.restitution
    want = (2 * 2 * math.log(e) - 0.75 * MAO.xi * T) / (2 * T)
    np.testing.assert_allclose(sw.lambda_max, want, atol=1e-8)
    assert round(want, 4) == -0.2239
    # the finite window's estimate oscillates around it (a complex pair, a short stretch)
    assert np.ptp(sw.lambda_window) > 1e-3
    assert not np.array_equal(sw.lambda_window, sw.lambda_max)


def test_cells_without_a_periodic_orbit_keep_the_window_estimate():
    sw = rockjit.sweep(Block(hb=1.0, law="housner"), Harmonic(omega=OMEGA),
                       rockjit.alpha_grid((0.50, 1.0), 0.01), integration=Integration(periods=300))
    other = ~np.isin(sw.label, PERIODIC)
    names = {str(n) for n in sw.names[sw.label[other]]}
    assert {"rest", "chaotic"} <= names  # the test sees both kinds
    np.testing.assert_array_equal(sw.lambda_max[other], sw.lambda_window[other])
    periodic = np.isin(sw.label, PERIODIC)
    assert periodic.sum() > 20
    # the periodic cells' exact exponents and the window's agree to the window's accuracy
    # (away from bifurcations, where a multiplier near the unit circle slows convergence)
    with np.errstate(invalid="ignore"):  # -inf - -inf: the rest cells, not compared here
        close = np.abs(sw.lambda_max - sw.lambda_window) < 0.05
    assert np.mean(close[periodic]) > 0.8


def test_every_plane_cell_is_its_own_system():
    pl = rockjit.plane(Block(hb=1.0), (0.55, 0.85), (1.2, 1.4), grid=(3, 3),
                       integration=Integration(periods=200))
    lab, per = pl.label[0], pl.period[0]
    th, dth, r0, s0 = -0.2254, -0.1597, -0.7778, 0.6284
    phi = math.atan2(r0, s0)
    checked = 0
    for i, a in enumerate(pl.alpha):
        for j, w in enumerate(pl.omega):
            if lab[i, j] not in PERIODIC:
                assert pl.lambda_max[0, i, j] == pl.lambda_window[0, i, j] or (
                    np.isnan(pl.lambda_max[0, i, j]) and np.isnan(pl.lambda_window[0, i, j]))
                continue
            r = rockjit.simulate(Block(hb=1.0), Harmonic(alpha=a, omega=w, phase=phi),
                                 (th, dth), integration=Integration(periods=200, n_steps=64))
            # the cell's own cycle, from a run of its own system
            p = int(per[i, j])
            _, lam = floquet(Block(hb=1.0), Harmonic(alpha=a, omega=w), phi,
                             Integration(), pl.settings["n_steps"], r.strobe[-1 - p, :2], p)
            assert pl.lambda_max[0, i, j] == pytest.approx(lam[0], abs=1e-6)
            checked += 1
    assert checked >= 3


def test_an_orbit_through_rest_has_exponent_minus_infinity():
    # the study's hb=1 basin holds a small orbit that comes to rest every half period
    b = rockjit.basin(Block(hb=1.0), Harmonic(alpha=0.66, omega=OMEGA), grid=16,
                      integration=Integration(periods=200), lyapunov=True)
    through_rest = [a for a in b.attractors if a.multipliers is not None
                    and np.all(a.multipliers == 0)]
    assert through_rest
    cells = np.isin(b.attractor, [a.id for a in through_rest])
    assert np.all(np.isneginf(b.lambda_max[cells]))
    rocking = [a for a in b.attractors if a.period and a not in through_rest]
    cells = np.isin(b.attractor, [a.id for a in rocking])
    assert np.all(np.isfinite(b.lambda_max[cells]))
