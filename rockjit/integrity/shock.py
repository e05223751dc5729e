"""The minimal fatal shock: the smallest perturbation of an attractor's state that overturns.

For a stroboscopic point ``x`` of an attractor, at the forcing's phase, the minimal fatal shock
is the perturbation ``delta = (d theta, d theta')`` of least Euclidean norm such that the run
from ``x + delta`` (same phase) overturns (Halekotte and Feudel 2020; Attractors.jl's
``minimal_fatal_shock``). It is searched without a lattice:

1. a coarse scan: ``directions`` rays from ``x``, ``radii`` radii on each up to ``radius``; on
   each ray the first fatal radius brackets a crossing of the boundary;
2. the rays within a few radial steps of the best are kept, and on each the crossing is
   narrowed by multisection (``K`` radii of the bracket run at once, the bracket shrunk to the
   first fatal one and the safe one before it);
3. the direction is refined by a pattern search (the two neighbouring angles at a step halved
   until ``angle_tol``), every trial ray scanned from ``x`` again so that a nearer crossing is
   not skipped, until the norm's bracket is within ``rtol`` of the norm.

The norm reported is the fatal end of the last bracket: ``x + delta`` was run and overturns, so
the norm is an upper bound of the true minimum that no lattice of initial states can undercut at
the resolution of the search; ``accuracy`` is the bracket's relative width along the ray.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..validate import integer, real
from .outcome import Outcomes

__all__ = ["FatalShock", "fatal_shock", "fatal_shock_chart", "fatal_shocks"]

#: Radii run at once in one round of multisection.
K = 15


@dataclass
class FatalShock:
    """A minimal fatal shock.

    Attributes
    ----------
    norm : float
        ``|delta|`` (Euclidean in ``(theta, theta')``); ``inf`` when no state within
        ``radius`` overturns.
    delta : ndarray, shape (2,)
        The perturbation: ``point + delta`` overturns.
    direction : ndarray, shape (2,)
        ``delta / norm``.
    accuracy : float
        Relative width of the last bracket along the ray: the state at ``norm * (1 -
        accuracy)`` in the same direction stays safe.
    point : ndarray, shape (2,)
        The attractor's point that was perturbed (of a cycle, its most exposed point).
    scaled : float or None
        ``norm / size`` where the attractor's size was given.
    angle_step : float
        The last step of the direction's search, in radians.
    runs : int
        Runs made.

    Examples
    --------
    What :func:`rockjit.fatal_shock` returns:

    >>> import rockjit
    >>> from rockjit import Block, Harmonic, Integration
    >>> s = rockjit.fatal_shock(Block(hb=1), Harmonic(alpha=0.66, omega=1.3), (0.0, 0.0),
    ...                         integration=Integration(periods=100), rtol=1e-3)
    >>> s.delta.shape, bool(abs(s.norm - float((s.delta ** 2).sum()) ** 0.5) < 1e-12)
    ((2,), True)
    """

    norm: float
    delta: np.ndarray
    direction: np.ndarray
    accuracy: float
    point: np.ndarray
    scaled: float | None = None
    angle_step: float = math.nan
    runs: int = 0
    settings: dict = field(default_factory=dict)

    def __repr__(self):
        d = ", ".join(f"{v:.4g}" for v in self.delta)
        return (f"<rockjit.FatalShock: norm {self.norm:.6g} (relative accuracy "
                f"{self.accuracy:.1e}), delta ({d}) from ({self.point[0]:.4g}, "
                f"{self.point[1]:.4g}), {self.runs} runs>")


def _units(angles):
    return np.column_stack([np.cos(angles), np.sin(angles)])


def _first_fatal(out, k_axis=1):
    """Index of the first ``True`` along axis 1, or -1 where none."""
    any_ = out.any(axis=k_axis)
    return np.where(any_, np.argmax(out, axis=k_axis), -1)


class _Search:
    """The boundary crossings of rays from one point (``oc``: :class:`Outcomes`)."""

    def __init__(self, oc, x):
        self.oc, self.x = oc, x

    def scan(self, angles, hi, n):
        """On each ray, ``n`` radii in ``(0, hi]``: ``(lo, hi)`` around the first fatal one
        (``hi = inf`` where none is fatal)."""
        u = _units(angles)
        r = np.asarray(hi, dtype=float)[:, None] * np.arange(1, n + 1)[None, :] / n
        z = self.x + r[..., None] * u[:, None, :]
        f = self.oc.fatal(z.reshape(-1, 2)).reshape(r.shape)
        k = _first_fatal(f)
        rows = np.arange(len(angles))
        new_hi = np.where(k >= 0, r[rows, np.maximum(k, 0)], np.inf)
        new_lo = np.where(k > 0, r[rows, np.maximum(k - 1, 0)], 0.0)
        return new_lo, new_hi

    def narrow(self, angles, lo, hi, rtol, atol=0.0):
        """Multisection of every finite bracket until ``hi - lo <= rtol * hi`` or
        ``hi - lo <= atol``."""
        lo, hi = lo.copy(), hi.copy()
        u = _units(angles)
        while True:
            todo = np.flatnonzero(np.isfinite(hi) & (hi - lo > np.maximum(rtol * hi, atol)))
            if todo.size == 0:
                return lo, hi
            t = np.arange(1, K + 1) / (K + 1)
            r = lo[todo, None] + (hi - lo)[todo, None] * t[None, :]
            z = self.x + r[..., None] * u[todo][:, None, :]
            f = self.oc.fatal(z.reshape(-1, 2)).reshape(r.shape)
            k = _first_fatal(f)
            rows = np.arange(todo.size)
            new_hi = np.where(k >= 0, r[rows, np.maximum(k, 0)], hi[todo])
            new_lo = np.where(k > 0, r[rows, np.maximum(k - 1, 0)],
                              np.where(k == 0, lo[todo], r[:, -1]))
            lo[todo], hi[todo] = new_lo, new_hi


def _one(oc, x, radius, directions, radii, rtol, angle_tol, keep):
    s = _Search(oc, x)
    angles = 2 * math.pi * np.arange(directions) / directions
    lo, hi = s.scan(angles, np.full(directions, radius), radii)
    if not np.isfinite(hi).any():
        return math.inf, np.full(2, np.nan), np.nan, angle_tol
    best = np.min(hi)
    cand = np.flatnonzero(hi <= best + keep * radius / radii)
    cand = cand[np.argsort(hi[cand])][:8]
    a, lo, hi = angles[cand], lo[cand], hi[cand]
    lo, hi = s.narrow(a, lo, hi, rtol)
    step = 0.5 * 2 * math.pi / directions
    while step >= angle_tol:
        trial = np.concatenate([a - step, a + step])
        cap = np.concatenate([hi, hi])
        tl, th = s.scan(trial, cap, radii)
        tl, th = s.narrow(trial, tl, th, rtol)
        moved = False
        for i in range(a.size):
            j = np.argmin([hi[i], th[i], th[i + a.size]])
            if j:
                jj = i if j == 1 else i + a.size
                a[i], lo[i], hi[i] = trial[jj], tl[jj], th[jj]
                moved = True
        if not moved:
            step *= 0.5
    i = int(np.argmin(hi))
    return float(hi[i]), _units(a[i:i + 1])[0], float((hi[i] - lo[i]) / hi[i]), step


def fatal_shock(block, forcing, point, *, radius=1.0, size=None, directions=48, radii=24,
                rtol=1e-4, angle_tol=1e-3, integration=None, classification=None,
                threads=None) -> FatalShock:
    """The minimal fatal shock of an attractor: the smallest perturbation of its stroboscopic
    point, at the same forcing phase, from which the block overturns.

    Parameters
    ----------
    block : Block
    forcing : Harmonic
        With ``alpha`` and ``omega``; its phase is the point's (default ``(r0, s0) = (0, 1)``,
        the basins').
    point : array_like, shape (2,) or (p, 2)
        ``(theta, theta')`` of the attractor at the forcing's phase; of a cycle, its ``p``
        points (the smallest shock over them is returned).
    radius : float
        Largest shock searched, ``> 0`` (default 1).
    size : float, optional
        The attractor's size, ``> 0``: ``scaled = norm / size``.
    directions, radii : int
        The coarse scan: rays (``>= 8``) and radii per ray (``>= 4``).
    rtol : float
        Relative width of the norm's last bracket, in ``[1e-12, 0.1]``.
    angle_tol : float
        Smallest step of the direction's search, radians, in ``[1e-8, 0.5]``.
    integration, classification :
        As in :func:`rockjit.basin`: ``integration.periods`` is the horizon within which a run
        must overturn to count as fatal.
    threads : int, optional
        Threads of the compiled runs.

    Returns
    -------
    FatalShock

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic, Integration
    >>> s = rockjit.fatal_shock(Block(hb=1), Harmonic(alpha=0.66, omega=1.3), (0.0, 0.0),
    ...                         integration=Integration(periods=100), rtol=1e-3)
    >>> s.accuracy <= 1e-3
    True
    """
    oc = Outcomes(block, forcing, integration, classification, threads)
    pts = np.atleast_2d(np.asarray(point, dtype=float))
    if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] == 0 or not np.isfinite(pts).all():
        raise ValueError(f"point must be (theta, theta') or rows of them (got {point!r})")
    radius = real("radius", radius, 0.0, 1e6, lo_open=True)
    if size is not None:
        size = real("size", size, 0.0, None, lo_open=True)
    directions = integer("directions", directions, 8, 100_000)
    radii = integer("radii", radii, 4, 100_000)
    rtol = real("rtol", rtol, 1e-12, 0.1)
    angle_tol = real("angle_tol", angle_tol, 1e-8, 0.5)
    if oc.fatal(pts).any():
        raise ValueError("point must be a state that does not overturn (the attractor's "
                         "point at the forcing's phase); a run from it overturns")
    best = None
    for x in pts:
        norm, u, acc, step = _one(oc, x, radius, directions, radii, rtol, angle_tol, keep=2)
        if best is None or norm < best[0]:
            best = (norm, u, acc, step, x)
    norm, u, acc, step, x = best
    return FatalShock(norm=norm, delta=norm * u if math.isfinite(norm) else u, direction=u,
                      accuracy=acc, point=x.copy(),
                      scaled=None if size is None else norm / size, angle_step=step,
                      runs=oc.runs, settings=dict(oc.settings, radius=radius, rtol=rtol,
                                                  directions=directions, radii=radii))


def _size(points):
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    return float(np.max(np.linalg.norm(p - p.mean(0), axis=1))) if len(p) > 1 else None


def fatal_shocks(basin_result, **kwargs):
    """The minimal fatal shock of every periodic or resting attractor of a basin result
    (:func:`rockjit.basin`), keyed by attractor id; ``kwargs`` as :func:`fatal_shock`
    (``integration`` defaults to the basin's periods)."""
    from ..settings import Integration
    b = basin_result
    kwargs.setdefault("integration", Integration(periods=b.settings["periods"]))
    out = {}
    for a in b.attractors:
        if a.behaviour in ("chaotic", "aperiodic"):
            continue
        pts = np.asarray(a.points, dtype=float).reshape(-1, 2)
        out[a.id] = fatal_shock(b.block, b.forcing, pts, size=_size(pts), **kwargs)
    return out


def fatal_shock_chart(chart, **kwargs):
    """``(na, nw)`` norms of the minimal fatal shock of the safe attractor with the largest
    basin at each forcing of an integrity chart (:func:`rockjit.safety`); ``nan`` where the
    basin has no periodic or resting attractor. ``kwargs`` as :func:`fatal_shock`."""
    from ..settings import Integration
    kwargs.setdefault("integration", Integration(periods=chart.settings["periods"]))
    norms = np.full(chart.safe.shape, np.nan)
    for i, a in enumerate(chart.alpha):
        for j, w in enumerate(chart.omega):
            rows = [r for r in chart.attractors[i][j]
                    if r["behaviour"] not in ("chaotic", "aperiodic")]
            if rows:
                f = chart.forcing.replace(alpha=float(a), omega=float(w))
                norms[i, j] = fatal_shock(chart.block, f, rows[0]["points"], **kwargs).norm
    return norms
