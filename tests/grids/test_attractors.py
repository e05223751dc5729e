"""Attractor identity against a slow readable matcher, symmetry and the scipy path.

- a plain-Python matcher over single ``simulate`` runs of a small grid gives the same attractor
  map as the compiled basin (up to the numbering);
- the block is symmetric under ``(theta, theta', t) -> (-theta, -theta', t + T/2)``: an
  asymmetric attractor's mirror image, half a period on, is an attractor of the same map;
- an attractor's Floquet multipliers against a finite-difference monodromy of the scipy path;
- fractions sum to 100 %; a sweep's ids follow its branches.
"""

import math

import numpy as np
import pytest

import rockjit
from rockjit import Block, Classification, Harmonic, Integration, Scipy
from rockjit.grids.identity import cycle_distance, identify, match_attractors

BLOCK = Block(hb=1.0, law="housner")  # the study's hb=1 basin
FORCING = Harmonic(alpha=0.66, omega=1.3)
SMALL = dict(grid=7, periods=300, n_steps=64)


def _basin(forcing=FORCING, grid=7, periods=300):
    return rockjit.basin(BLOCK, forcing, grid, integration=Integration(periods=periods))


def _slow_attractor_map(theta0, dtheta0, periods, n_steps, tol=1e-4):
    """One ``simulate`` run per cell; cycles matched in plain Python (any cyclic shift)."""
    known = []  # (behaviour, period, cycle)
    ids = np.empty((theta0.size, dtheta0.size), dtype=int)
    for i, th in enumerate(theta0):
        for j, dth in enumerate(dtheta0):
            r = rockjit.simulate(BLOCK, FORCING.replace(r0=0.0, s0=1.0), (th, dth),
                                 integration=Integration(periods=periods, n_steps=n_steps))
            name, p = rockjit.classify_result(r)
            if name == "overturn":
                ids[i, j] = -1
                continue
            if name == "rest":
                key = ("rest", 0, None)
            elif p >= 1:
                key = (name, p, r.strobe[-p:, :2].copy())
            else:
                ids[i, j] = -3  # clouds are not exercised by this grid
                continue
            for k, (kn, kp, kc) in enumerate(known):
                if kn != key[0] or kp != key[1]:
                    continue
                if kn == "rest":
                    ids[i, j] = k
                    break
                size = max(np.abs(kc).max(), np.abs(key[2]).max())
                shifts = [max(abs(kc[(m + s) % kp, c] - key[2][m, c])
                              for m in range(kp) for c in range(2)) for s in range(kp)]
                if min(shifts) <= tol * size:
                    ids[i, j] = k
                    break
            else:
                known.append(key)
                ids[i, j] = len(known) - 1
    return ids, known


def test_compiled_attractor_map_equals_a_slow_matcher():
    b = rockjit.basin(BLOCK, FORCING, SMALL["grid"],
                      integration=Integration(periods=SMALL["periods"], n_steps=SMALL["n_steps"]),
                      classification=Classification(early_stop=False))
    slow, known = _slow_attractor_map(b.theta0, b.dtheta0, SMALL["periods"], SMALL["n_steps"])
    assert len(known) >= 2  # the map holds at least two attractors (a non-trivial test)
    fast = b.attractor
    # the same partition of the cells: a bijection between the two numberings
    for v in np.unique(slow):
        assert np.unique(fast[slow == v]).size == 1, v
    for v in np.unique(fast):
        assert np.unique(slow[fast == v]).size == 1, v
    assert np.array_equal(fast == -1, slow == -1)


def test_fractions_sum_to_100_and_ids_follow_basin_size():
    b = _basin(grid=30)
    fr = [a.fraction for a in b.attractors]
    other = 100.0 * np.mean(b.attractor < 0)
    assert sum(fr) + other == pytest.approx(100.0)
    assert fr == sorted(fr, reverse=True)
    for a in b.attractors:
        assert a.n_cells == np.count_nonzero(b.attractor == a.id)


def _half_period_image(point, phase, p):
    """The cycle through ``point`` sampled half a period later, ``p`` points."""
    r = rockjit.simulate(BLOCK, Harmonic(alpha=0.8, omega=FORCING.omega, phase=phase),
                         (point[0], point[1]), integration=Integration(periods=p + 1, n_steps=64))
    return r.strobe_half[:p, :2]


def test_asymmetric_attractors_come_in_mirror_pairs():
    b = _basin(FORCING.replace(alpha=0.8), grid=24)
    asym = [a for a in b.attractors if a.behaviour == "asymmetric"]
    assert len(asym) == 2
    for a in asym:
        mirror = -_half_period_image(a.points[0], 0.0, a.period)
        others = [o for o in asym if o.id != a.id]
        d = min(cycle_distance(o.points, mirror) for o in others)
        assert d <= 1e-4 * np.abs(a.points).max()
        assert cycle_distance(a.points, mirror) > 1e-2  # not its own mirror image


def test_floquet_multipliers_match_the_scipy_monodromy():
    b = _basin(grid=12)
    a = next(x for x in b.attractors if x.behaviour == "symmetric" and x.multipliers[0] != 0)
    x = a.points[0]

    def one_period(y):
        r = rockjit.simulate(BLOCK, FORCING.replace(phase=0.0), (y[0], y[1]),
                             integration=Integration(periods=1),
                             method=Scipy("DOP853", rtol=1e-12, atol=1e-12))
        return r.state[:2]

    eps = 1e-6
    J = np.column_stack([(one_period(x + d) - one_period(x - d)) / (2 * eps)
                         for d in (np.array([eps, 0.0]), np.array([0.0, eps]))])
    mu = np.linalg.eigvals(J)
    np.testing.assert_allclose(np.sort(np.abs(mu)), np.sort(np.abs(a.multipliers)), rtol=1e-4)
    # and its exponents are ln|mu| / T: those of a long run on it
    r = rockjit.simulate(BLOCK, FORCING.replace(phase=0.0), (x[0], x[1]), lyapunov=True,
                         integration=Integration(n_steps=64))
    np.testing.assert_allclose(a.lam, r.lyapunov, rtol=1e-3)


def test_identify_on_synthetic_cycles():
    # three cells on one period-2 cycle, sampled at different shifts and with 1e-7 noise, and a
    # cell on another cycle: two attractors; overturn and unresolved keep their ids
    c = np.array([[0.3, -0.2], [-0.1, 0.4]])
    pts = np.full((6, 4, 2), np.nan)
    pts[0, :4] = np.vstack([c, c])
    pts[1, :3] = np.vstack([c[1:], c])
    pts[2, :2] = c + 1e-7
    pts[3, :2] = c * 1.5
    label = np.array([4, 4, 4, 4, 0, 7])  # multiperiodic x4, overturn, unresolved
    period = np.array([2, 2, 2, 2, 0, 0])
    n_got = np.array([4, 3, 2, 2, 0, 0])
    ids, found = identify(label, period, pts, n_got)
    assert ids.tolist() == [0, 0, 0, 1, -1, -2]
    assert [a.n_cells for a in found] == [3, 1]


def test_sweep_ids_follow_its_branches():
    sw = rockjit.sweep(BLOCK, Harmonic(omega=1.3), rockjit.alpha_grid((0.70, 0.86), 0.004),
                       integration=Integration(periods=300))
    ids = sw.attractor
    names = sw.names[sw.label]
    # one id never mixes behaviours, and each id is one contiguous run of amplitudes
    for a in sw.attractors:
        cells = np.flatnonzero(ids == a.id)
        assert set(names[cells]) == {a.behaviour}
        assert np.array_equal(cells, np.arange(cells[0], cells[-1] + 1))
    assert {"symmetric", "asymmetric"} <= {a.behaviour for a in sw.attractors}


def test_two_laws_attractors_are_matched_by_their_cycles():
    a = _basin(grid=10)
    pairs = match_attractors(a.attractors, a.attractors)
    assert pairs == {x.id: x.id for x in a.attractors}
    moved = [type(x)(**{**x.__dict__, "points": x.points + 0.05}) for x in a.attractors]
    assert all(match_attractors(a.attractors, moved).get(x.id) is None
               for x in a.attractors if x.period)


@pytest.mark.parametrize("grid", [1, 2, 3])
def test_measures_of_tiny_maps_are_defined(grid):
    m = _basin(grid=grid, periods=20).measures()
    assert set(m) >= {"basin_entropy", "boundary_basin_entropy", "integrity",
                      "uncertainty_exponent"}
    assert 0.0 <= m["integrity"]["GIM"] <= 1.0
