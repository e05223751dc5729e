"""Where the cells of a grid lie when it is drawn as an image or a mesh: the edges around its
points and an image's extent."""

from __future__ import annotations

import numpy as np

__all__ = ["edges", "extent"]


def edges(x, lone=0.5, lone_ratio=None):
    """Cell edges around the increasing points ``x``: the midpoints, and as far beyond each end
    as the nearest midpoint is inside it. A single point gets ``lone`` either side, or, with
    ``lone_ratio`` and a positive point, ``x (1 -+ lone_ratio)`` (a cell on a log axis)."""
    x = np.asarray(x, dtype=float)
    if x.size == 1:
        if lone_ratio is not None and x[0] > 0:
            return np.array([x[0] * (1.0 - lone_ratio), x[0] * (1.0 + lone_ratio)])
        return np.array([x[0] - lone, x[0] + lone])
    mid = 0.5 * (x[1:] + x[:-1])
    return np.concatenate([[x[0] - (mid[0] - x[0])], mid, [x[-1] + (x[-1] - mid[-1])]])


def extent(x, y):
    """``imshow`` extent of a grid over axes ``x, y``: half a cell beyond the end points (half
    a unit for an axis of one point, or of equal points, so the extent is never empty)."""
    def half(v):
        return (v[-1] - v[0]) / (len(v) - 1) / 2 if len(v) > 1 and v[-1] > v[0] else 0.5
    dx, dy = half(x), half(y)
    return (x[0] - dx, x[-1] + dx, y[0] - dy, y[-1] + dy)
