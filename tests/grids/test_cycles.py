"""The one cycle matcher (rockjit.grids.cycles) against a plain-Python brute force: every cyclic
shift, stacks broadcast, symmetric bit for bit; and the distance of two attractors built on it."""

import math

import numpy as np
import pytest

from rockjit.grids.cycles import cycle_distance, cycle_size
from rockjit.grids.identity import Attractor, attractor_distance, match_attractors


def brute(a, b):
    """min over shifts s of max |a[i] - b[(i + s) mod p]|, in plain Python."""
    p = len(a)
    return min(max(abs(a[i][k] - b[(i + s) % p][k]) for i in range(p) for k in range(2))
               for s in range(p))


@pytest.mark.parametrize("p", [1, 2, 3, 7])
def test_cycle_distance_is_the_brute_force_minimum_over_shifts(p):
    rng = np.random.default_rng(p)
    a = rng.normal(size=(p, 2))
    stack = rng.normal(size=(5, p, 2))
    stack[2] = np.roll(a, 1, axis=0)  # a shift of a itself
    got = cycle_distance(a, stack)
    assert got.shape == (5,)
    for k in range(5):
        want = brute(a.tolist(), stack[k].tolist())
        assert got[k] == want
        assert cycle_distance(a, stack[k]) == want == cycle_distance(stack[k], a)
    assert got[2] == 0.0
    # stacks against stacks, pair by pair
    other = rng.normal(size=(5, p, 2))
    pairs = cycle_distance(stack, other)
    assert [pairs[k] for k in range(5)] == [cycle_distance(stack[k], other[k]) for k in range(5)]


def test_a_non_finite_point_never_matches():
    a = np.array([[0.1, 0.2], [math.nan, 0.0]])
    assert not cycle_distance(a, a) <= 1.0
    assert float(cycle_size([[0.1, -0.3]])) == 0.3


def _attractor(behaviour, points, id_=0):
    points = np.asarray(points, dtype=float)
    period = 0 if behaviour in ("rest", "chaotic", "aperiodic") else points.shape[0]
    return Attractor(id=id_, behaviour=behaviour, period=period, points=points,
                     fraction=50.0, n_cells=1, lam=np.zeros(2))


def test_attractor_distance_by_kind():
    c1 = _attractor("asymmetric", [[0.2, 0.1]])
    c2 = _attractor("asymmetric", [[0.1, 0.1]], 1)
    assert attractor_distance(c1, c2) == attractor_distance(c2, c1) == 0.5
    assert attractor_distance(c1, _attractor("symmetric", [[0.2, 0.1]])) is None
    assert attractor_distance(_attractor("rest", [[0, 0]]), _attractor("rest", [[0, 0]])) == 0
    cloud_a = _attractor("chaotic", [[0.0, 0.0], [0.4, 0.2]])
    cloud_b = _attractor("chaotic", [[0.1, 0.0], [0.5, 0.2]])
    assert attractor_distance(cloud_a, cloud_b) == pytest.approx(0.1 / 0.5)
    # the floor bounds the size from below
    assert attractor_distance(c1, c2, floor=1.0) == pytest.approx(0.1)


def test_match_attractors_pairs_cycles_and_rest_but_not_clouds():
    a = [_attractor("asymmetric", [[0.2, 0.1]], 0), _attractor("rest", [[0, 0]], 1),
         _attractor("chaotic", [[0.0, 0.0], [0.4, 0.2]], 2)]
    b = [_attractor("chaotic", [[0.0, 0.0], [0.4, 0.2]], 0), _attractor("rest", [[0, 0]], 1),
         _attractor("asymmetric", [[0.2, 0.1 + 1e-7]], 2)]
    assert match_attractors(a, b) == {0: 2, 1: 1}
