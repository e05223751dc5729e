"""Erosion profiles: the stacked computation against separate basins, the measures against
rockjit.basins.measures on each basin, and the continued branches' bookkeeping."""

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic, Integration
from rockjit.basins import erosion as er
from rockjit.basins import measures as M

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


def test_a_branch_is_one_orbit_moving_a_little():
    # the symmetric orbit of the study's hb=1 Housner basin continues across 0.60..0.72: one
    # branch spanning every amplitude, whose cycle moves by less than the continuation tolerance
    p = _erosion()
    spans = [b for b in p.branches if b["behaviour"] == "symmetric" and
             b["alpha"] == [p.alpha[0], p.alpha[-1]]]
    assert spans


def test_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="alpha_step"):
        _erosion(alpha_step=0.0)
    with pytest.raises(ValueError, match="grid"):
        _erosion(grid=0)
    with pytest.raises(ValueError, match="would need"):
        _erosion(grid=100_000)
