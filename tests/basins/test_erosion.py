"""Erosion profiles: the stacked computation against separate basins, the measures against
rockjit.measures on each basin, and the continued branches' bookkeeping."""

import math

import numpy as np
import pytest

import physics as ph  # tests/physics.py: the independent statement of the physics

import rockjit
from rockjit import Block, Harmonic, Integration
from rockjit.basins import erosion as er
from rockjit import measures as M

BLOCK = Block(hb=1.0, law="housner")
FORCING = Harmonic(omega=1.3)
KW = dict(alpha_range=(0.60, 0.72), alpha_step=0.04, grid=16, periods=200)


def _erosion(alpha_step=KW["alpha_step"], grid=KW["grid"]):
    return er.erosion(BLOCK, FORCING, rockjit.alpha_grid(KW["alpha_range"], alpha_step), grid,
                      integration=Integration(periods=KW["periods"]))


@pytest.fixture(scope="module")
def profile():
    return _erosion()


def test_each_amplitude_is_the_basin_computed_alone(profile):
    for k, alpha in enumerate(profile.alpha):
        b = rockjit.basin(BLOCK, FORCING.replace(alpha=float(alpha)), KW["grid"],
                          integration=Integration(periods=KW["periods"]))
        np.testing.assert_array_equal(profile.label[k], b.label)
        # the same partition into attractors (branch ids number them differently)
        for v in np.unique(b.attractor):
            assert np.unique(profile.attractor[k][b.attractor == v]).size == 1
        integ = M.integrity(b.attractor, b.theta0, b.dtheta0)
        assert profile.GIM[k] == pytest.approx(integ.GIM)
        assert profile.IF[k] == pytest.approx(integ.IF)
        assert profile.basin_entropy[k] == pytest.approx(M.basin_entropy(b.attractor).Sb)


def test_fractions_and_overturn_add_up(profile):
    total = profile.fractions().sum(axis=0) + profile.overturn + \
        100.0 * np.mean(profile.attractor == -2, axis=(1, 2))
    np.testing.assert_allclose(total, 100.0)
    for b in profile.branches:
        k = np.flatnonzero(b["fraction"] > 0)
        assert profile.alpha[k[0]] == b["alpha"][0] and profile.alpha[k[-1]] == b["alpha"][1]
        for j in k:  # the map holds exactly that share of the branch's id
            assert 100.0 * np.mean(profile.attractor[j] == b["id"]) == \
                pytest.approx(b["fraction"][j])


def _params(alpha, phi):
    return dict(hb=BLOCK.hb, alpha=alpha, omega=FORCING.omega, law=BLOCK.law, xi=BLOCK.xi,
                phi=phi)


def _fixed_point(x, alpha, phi):
    """The fixed point near ``x`` of the stroboscopic map of tests/physics.py (a slow
    solve_ivp integration sharing no code with rockjit), by Newton's method on its
    finite-difference Jacobian."""
    x = np.asarray(x, dtype=float)
    for _ in range(8):
        M, y = ph.monodromy_fd(x, 1, **_params(alpha, phi))
        step = np.linalg.solve(M - np.eye(2), y - x)
        x = x - step
        if np.abs(step).max() <= 1e-12:
            return x
    raise AssertionError(f"no fixed point near {x} at alpha = {alpha}")


def test_a_branch_is_one_orbit_moving_a_little(profile, spec):
    """The symmetric orbit of the study's hb=1 Housner basin continues across 0.60..0.72: one
    period-1 branch spanning every amplitude and holding cells at each, whose cycle moves by
    less than the continuation tolerance from one amplitude to the next.

    The cycle is found again at each amplitude, independently, as the fixed point of
    tests/physics.py's stroboscopic map (Newton continued from the branch's own point at the
    first amplitude); half a period on, conftest's ``spec`` integration puts it at its mirror
    image (a symmetric orbit); and a cell the branch holds at that amplitude, run on its own,
    settles onto that fixed point. Measured: the mirror image to 5e-14 of the orbit's size, the
    branch's point to 8e-10 (the basins' N = 64), the settled cells to 7e-12; the cycle moves
    by 0.11-0.17 of its size per amplitude step (the tolerance: 0.35)."""
    p = profile
    spans = [b for b in p.branches if b["behaviour"] == "symmetric" and
             b["alpha"] == [p.alpha[0], p.alpha[-1]]]
    assert len(spans) == 1
    br = spans[0]
    assert br["period"] == 1 and np.all(np.asarray(br["fraction"]) > 0)
    phi = FORCING.start()[0]  # the basins' forcing phase
    T = 2 * math.pi / FORCING.omega
    x = np.asarray(br["points"][0], dtype=float)
    prev = None
    for k, alpha in enumerate(map(float, p.alpha)):
        x = _fixed_point(x, alpha, phi)
        size = np.abs(x).max()
        assert size > 0.05  # a rocking orbit, not rest
        half = spec.run(BLOCK.hb, alpha, FORCING.omega, spec.e_housner(BLOCK.hb),
                        theta0=x[0], dtheta0=x[1], phi=phi, t_end=T / 2, xi=BLOCK.xi)
        assert np.abs(half["y"] + x).max() <= 1e-11 * size, (half["y"], x)
        if k == 0:
            # the branch starts at the cycle's point (rockjit's grid run, N = 64)
            assert np.abs(np.asarray(br["points"][0]) - x).max() <= 1e-8 * size
        else:
            # moving a little: within the continuation tolerance of the last amplitude's cycle
            assert np.abs(x - prev).max() <= p.settings["cont_tol"] * size
        prev = x
        cells = np.argwhere(p.attractor[k] == br["id"])
        i, j = cells[len(cells) // 2]
        r = rockjit.simulate(BLOCK, FORCING.replace(alpha=alpha),
                             (float(p.theta0[i]), float(p.dtheta0[j])),
                             integration=Integration(periods=KW["periods"]))
        assert np.abs(r.strobe[-1, :2] - x).max() <= 1e-9 * size


def test_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="alpha_step"):
        _erosion(alpha_step=0.0)
    with pytest.raises(ValueError, match="grid"):
        _erosion(grid=0)
    with pytest.raises(ValueError, match="would need"):
        _erosion(grid=100_000)
