"""Cycles of the stroboscopic map compared as sets: the one cyclic-shift distance.

A period-``p`` cycle is ``p`` points ``(theta, theta')`` at ``t = kT``; which of them comes first
depends only on when sampling began, so two cycles are compared under every cyclic shift. The
attractor identity of the grids (:mod:`rockjit.grids.identity`), the erosion profiles'
continuation (:mod:`rockjit.basins.erosion`) and the branches of periodic orbits
(:mod:`rockjit.orbits`) all measure cycles with :func:`cycle_distance`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["cycle_distance", "cycle_size"]


def cycle_distance(a, b):
    """Smallest over cyclic shifts of the largest point-wise difference of two cycles.

    Parameters
    ----------
    a, b : array_like, shape (..., p, 2)
        Cycles (or stacks of them, broadcast against each other).

    Returns
    -------
    float or ndarray
        ``min over s of max |a - roll(b, s)|``: a float for two single cycles, else an array of
        the broadcast stack's shape. Exact (no rounding: a difference and its magnitude), so
        symmetric in ``a`` and ``b`` bit for bit.

    Examples
    --------
    >>> from rockjit.grids.cycles import cycle_distance
    >>> cycle_distance([[0.1, 0.0], [-0.1, 0.0]], [[-0.1, 0.0], [0.1, 0.0]])
    0.0
    >>> cycle_distance([[0.1, 0.0]], [[[0.1, 0.0]], [[0.3, 0.0]]]).round(12).tolist()
    [0.0, 0.2]
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    best = np.full(np.broadcast_shapes(a.shape, b.shape)[:-2], np.inf)
    for s in range(a.shape[-2]):
        best = np.minimum(best, np.abs(np.roll(b, -s, axis=-2) - a).max(axis=(-2, -1)))
    return float(best) if best.ndim == 0 else best


def cycle_size(c):
    """The size of a cycle (or of each of a stack): its largest ``|theta|, |theta'|``.

    Examples
    --------
    >>> from rockjit.grids.cycles import cycle_size
    >>> float(cycle_size([[0.1, -0.4], [-0.1, 0.4]]))
    0.4
    """
    return np.abs(np.asarray(c, dtype=float)).max(axis=(-2, -1))
