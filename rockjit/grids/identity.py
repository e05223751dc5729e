"""Attractor identity: which attractor each cell of a grid reaches, and what each attractor is.

The grid kernels classify a cell by its behaviour (:mod:`rockjit._engine.classify`); this module names
the *attractor*: two cells of a basin reach the same attractor when their settled stroboscopic
cycles coincide (docs/theory/global-dynamics.md). Outcome ids: ``>= 0`` attractors (numbered by decreasing basin
size; rest for good is one), ``-1`` overturn, ``-2`` unresolved.

The rules (documented in the README, "Attractors"):

- **Periodic cells** (symmetric, asymmetric, multiperiodic, period ``p``): the cycle is the
  last ``p`` samples at ``t = kT`` of the classified stretch, a set (any cyclic shift is the
  same cycle). Within one system (a basin) two cycles are the same attractor when they have the
  same period and some cyclic shift brings every point within ``tol`` times the orbit's size
  (the largest ``|theta|, |theta'|`` of either cycle) of the other's; the early stop settles a
  cycle to ``1e-9`` of its size, so ``tol = 1e-4`` separates distinct orbits, whose points lie
  ``O(1)`` apart, with a wide margin.
- **Rest for good** is one attractor (the block at rest, never lifted again).
- **Chaotic and aperiodic cells**: their last ``pmax`` samples at ``kT`` (a sample of the
  cloud) are rasterised on a coarse ``cloud_grid x cloud_grid`` grid over the box holding every
  such sample of the map; cells of the same behaviour whose clouds share a coarse cell are
  joined, transitively (connected components): one chaotic attractor's cells form one group, as
  in Attractors.jl's recurrence-based mapper, where a coarse cell visited by two trajectories
  makes them one attractor.
- **Across a parameter** (sweeps and planes, where every cell is another system): neighbouring
  cells along the grid continue the same attractor when they have the same behaviour and
  period and their cycles lie within ``cont_tol`` of each other's size (default 0.1: a step of
  the parameter moves a cycle a little, a jump to another attractor moves it ``O(1)``).

Per attractor: its behaviour, period, cycle points, fraction of the cells, exponents and, for
periodic ones, its Floquet multipliers from the tangent over ``p`` periods on the cycle
(:func:`floquet`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..result import (APERIODIC, ASYMMETRIC, BEHAVIOURS, CHAOTIC, MULTIPERIODIC, OVERTURN,
                     REST, SYMMETRIC, UNRESOLVED)
from .cycles import cycle_distance, cycle_size

__all__ = ["CLOUD_GRID", "CONT_TOL", "MATCH_TOL", "OVERTURN_ID", "UNRESOLVED_ID", "Attractor",
           "agreement", "attractor_agreement", "attractor_distance", "cycle_distance", "cycles_differ",
           "floquet", "identify", "identify_along", "match_attractors"]

#: Outcome ids of the cells that reach no attractor.
OVERTURN_ID = -1
UNRESOLVED_ID = -2
#: Matching tolerance of two cycles of one system, relative to the orbit's size.
MATCH_TOL = 1e-4
#: Continuation tolerance between neighbouring cells of a sweep or plane.
CONT_TOL = 0.1
#: Coarse grid of the chaotic/aperiodic clouds.
CLOUD_GRID = 16

_PERIODIC = (SYMMETRIC, ASYMMETRIC, MULTIPERIODIC)
_CLOUD = (CHAOTIC, APERIODIC)


@dataclass
class Attractor:
    """One attractor of a grid's map.

    Attributes
    ----------
    id : int
        Its outcome id (``>= 0``).
    behaviour : str
        The behaviour of its cells (:data:`rockjit.result.BEHAVIOURS`).
    period : int
        Its period in forcing periods (0 for rest, chaotic and aperiodic ones).
    points : ndarray, shape (p, 2)
        Its cycle at ``t = kT`` (``theta, theta'``); for a cloud, its cells' samples (up to 64).
    fraction : float
        Percent of the grid's cells that reach it.
    n_cells : int
        Number of cells that reach it.
    lam : ndarray, shape (2,)
        ``(lambda1, lambda2)``: ``ln|mu| / (pT)`` of its multipliers for periodic ones, the mean
        over its cells where the grid computed exponents otherwise (``-inf`` for rest, ``nan``
        when unknown).
    multipliers : ndarray of complex, shape (2,) or None
        Floquet multipliers of a periodic attractor (eigenvalues of the tangent over ``p``
        periods from a cycle point, saltation at every impact).
    cell : int
        Flat index of one of its cells (its representative).
    extent : tuple or None
        Along a sweep or plane: the first and last grid index (flat) it spans.
    """

    id: int
    behaviour: str
    period: int
    points: np.ndarray
    fraction: float
    n_cells: int
    lam: np.ndarray
    multipliers: np.ndarray | None = None
    cell: int = -1
    extent: tuple | None = None

    @property
    def name(self):
        """Its name: the behaviour, with the period for a periodic one (``"symmetric p=1"``;
        ``"rest"``, ``"chaotic"``)."""
        return self.behaviour if self.behaviour == "rest" or not self.period else \
            f"{self.behaviour} p={self.period}"

    def __repr__(self):
        from ..reprs import text
        return text(self)

    def to_dict(self):
        """JSON-ready (complex multipliers as ``[re, im]`` pairs)."""
        mu = None if self.multipliers is None else \
            [[float(np.real(m)), float(np.imag(m))] for m in self.multipliers]
        d = dict(id=int(self.id), behaviour=self.behaviour, period=int(self.period),
                 points=np.asarray(self.points).tolist(), fraction=float(self.fraction),
                 n_cells=int(self.n_cells), **{"lambda": [float(v) for v in self.lam]},
                 multipliers=mu)
        if self.extent is not None:
            d["extent"] = [int(v) for v in self.extent]
        return d


def _cycles(pts, n_got, period):
    """The last ``period`` points of each cell's samples: ``(n, p, 2)``."""
    idx = n_got[:, None] - period + np.arange(period)[None, :]
    return np.take_along_axis(pts, idx[:, :, None], axis=1)


def _periodic_groups(idx, cyc, tol):
    """Greedy grouping of the cycles ``cyc`` (cells ``idx``) of one period: the first
    ungrouped cycle and every cycle within ``tol`` of it form a group."""
    groups = []
    left = np.arange(idx.size)
    scale = cycle_size(cyc)
    while left.size:
        ref = cyc[left[0]]
        d = cycle_distance(ref, cyc[left])
        near = d <= tol * np.maximum(np.maximum(scale[left], scale[left[0]]), 1e-12)
        near[0] = True
        groups.append(idx[left[near]])
        left = left[~near]
    return groups


def _valid(pts, n_got):
    """Mask of the valid samples of each cell: ``(n, m)``."""
    return np.arange(pts.shape[1])[None, :] < np.asarray(n_got)[:, None]


def _cloud_groups(idx, pts, n_got, label, grid):
    """Connected components of the cells ``idx`` whose clouds share a coarse cell (same
    behaviour only)."""
    if idx.size == 0:
        return []
    P = pts[idx]
    ok = _valid(P, n_got[idx])
    if not ok.any():
        return [np.array([i]) for i in idx]
    lo = P[ok].min(axis=0)
    span = np.maximum(P[ok].max(axis=0) - lo, 1e-12)
    q = np.clip(((np.nan_to_num(P) - lo) / span * grid).astype(np.int64), 0, grid - 1)
    kind = np.searchsorted(np.array(_CLOUD), label[idx])  # 0 chaotic, 1 aperiodic
    box = (q[..., 0] * grid + q[..., 1]) * len(_CLOUD) + kind[:, None]
    n = idx.size
    rows = np.broadcast_to(np.arange(n)[:, None], box.shape)[ok]
    nb = grid * grid * len(_CLOUD)
    graph = coo_matrix((np.ones(rows.size), (rows, n + box[ok])), shape=(n + nb, n + nb))
    _, comp = connected_components(graph, directed=False)
    comp = comp[:n]
    return [idx[comp == c] for c in np.unique(comp)]


def identify(label, period, pts, n_got, lam=None, *, tol=MATCH_TOL, cloud_grid=CLOUD_GRID):
    """Attractor ids of the cells of one system's map (a basin), and the attractors.

    Parameters
    ----------
    label, period : ndarray of int, shape (n,)
        Behaviour codes and periods of the cells (flat).
    pts : ndarray, shape (n, m, 2)
        Each cell's last samples at ``kT`` over its classified stretch (``m >= pmax``), the
        first ``n_got[i]`` valid.
    n_got : ndarray of int, shape (n,)
    lam : ndarray, shape (n, 2), optional
        The cells' exponents, when the grid computed them.
    tol, cloud_grid : float, int
        The matching tolerance and the clouds' coarse grid (module docstring).

    Returns
    -------
    ids : ndarray of int, shape (n,)
    attractors : list of Attractor
        Without multipliers (see :func:`floquet`); ordered by id.
    """
    label = np.asarray(label)
    period = np.asarray(period)
    n = label.size
    ids = np.full(n, UNRESOLVED_ID, dtype=np.int64)
    ids[label == OVERTURN] = OVERTURN_ID
    groups = []  # (cells, behaviour code, period)
    rest = np.flatnonzero(label == REST)
    if rest.size:
        groups.append((rest, REST, 0))
    periodic = np.isin(label, _PERIODIC) & (n_got >= np.maximum(period, 1))
    for p in np.unique(period[periodic]):
        idx = np.flatnonzero(periodic & (period == p))
        cyc = _cycles(pts[idx], n_got[idx], int(p))
        for g in _periodic_groups(idx, cyc, tol):
            groups.append((g, int(label[g[0]]), int(p)))
    cloud = np.flatnonzero(np.isin(label, _CLOUD))
    for g in _cloud_groups(cloud, pts, n_got, label, cloud_grid):
        groups.append((g, int(label[g[0]]), 0))
    # ids by decreasing size (ties: the first cell), so that the largest basin is attractor 0
    groups.sort(key=lambda g: (-g[0].size, int(g[0].min())))
    attractors = []
    for k, (cells, code, p) in enumerate(groups):
        ids[cells] = k
        rep = int(cells.min())
        if code == REST:
            points = np.zeros((1, 2))
        elif p:
            points = _cycles(pts[rep:rep + 1], n_got[rep:rep + 1], p)[0]
        else:
            points = np.concatenate([pts[i, :n_got[i]] for i in cells[:4]])[:64]
        if code == REST:
            lam_k = np.array([-math.inf, -math.inf])
        elif lam is not None:
            lam_k = np.nanmean(np.asarray(lam)[cells], axis=0) if np.isfinite(
                np.asarray(lam)[cells]).any() else np.array([math.nan, math.nan])
        else:
            lam_k = np.array([math.nan, math.nan])
        attractors.append(Attractor(id=k, behaviour=BEHAVIOURS[code], period=p,
                                    points=np.asarray(points, dtype=float),
                                    fraction=100.0 * cells.size / n, n_cells=int(cells.size),
                                    lam=np.asarray(lam_k, dtype=float), cell=rep))
    return ids, attractors


def identify_along(label, period, pts, n_got, shape, *, tol=CONT_TOL, lam=None):
    """Attractor ids across a parameter grid (a sweep, or a plane), by continuation.

    Neighbouring cells (along each axis of ``shape``) are the same attractor when they have the
    same behaviour and period and their cycles (last ``p`` samples; for clouds, the centroid of
    their samples) lie within ``tol`` of the orbit's size. Rest joins rest; overturn and
    unresolved cells get ``-1`` and ``-2``. Returns ``(ids, attractors)`` as :func:`identify`,
    each attractor with its ``extent`` (first and last flat index).
    """
    label = np.asarray(label).ravel()
    period = np.asarray(period).ravel()
    n = label.size
    bounded = np.isin(label, _PERIODIC + _CLOUD + (REST,))
    rows, cols = [], []
    grid = np.arange(n).reshape(shape)
    for ax in range(len(shape)):
        a = np.take(grid, range(shape[ax] - 1), axis=ax).ravel()
        b = np.take(grid, range(1, shape[ax]), axis=ax).ravel()
        same = bounded[a] & bounded[b] & (label[a] == label[b]) & (period[a] == period[b])
        a, b = a[same], b[same]
        keep = _continues(a, b, label, period, pts, n_got, tol)
        rows.append(a[keep])
        cols.append(b[keep])
    rows = np.concatenate(rows) if rows else np.zeros(0, np.int64)
    cols = np.concatenate(cols) if cols else np.zeros(0, np.int64)
    graph = coo_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n))
    _, comp = connected_components(graph, directed=False)
    ids = np.full(n, UNRESOLVED_ID, dtype=np.int64)
    ids[label == OVERTURN] = OVERTURN_ID
    groups = [np.flatnonzero((comp == c) & bounded) for c in np.unique(comp[bounded])]
    groups.sort(key=lambda g: (-g.size, int(g.min())))
    attractors = []
    for k, cells in enumerate(groups):
        ids[cells] = k
        rep = int(cells[cells.size // 2])
        code = int(label[rep])
        p = int(period[rep]) if code in _PERIODIC else 0
        if code == REST:
            points = np.zeros((1, 2))
        elif p:
            points = _cycles(pts[rep:rep + 1], n_got[rep:rep + 1], p)[0]
        else:
            points = pts[rep, :n_got[rep]][:64]
        lam_k = np.array([-math.inf, -math.inf]) if code == REST else (
            np.asarray(lam).reshape(n, -1)[rep, :2] if lam is not None
            else np.array([math.nan, math.nan]))
        attractors.append(Attractor(id=k, behaviour=BEHAVIOURS[code], period=p,
                                    points=np.asarray(points, dtype=float),
                                    fraction=100.0 * cells.size / n, n_cells=int(cells.size),
                                    lam=np.asarray(lam_k, dtype=float), cell=rep,
                                    extent=(int(cells.min()), int(cells.max()))))
    return ids, attractors


def _continues(a, b, label, period, pts, n_got, tol):
    """Which neighbour pairs ``(a[k], b[k])`` (same behaviour and period) continue one
    attractor: rest always; cycles (periodic) or cloud centroids within ``tol`` of the size."""
    keep = np.zeros(a.size, dtype=bool)
    code = label[a]
    keep[code == REST] = True
    for p in np.unique(period[a][np.isin(code, _PERIODIC)]):
        k = np.flatnonzero(np.isin(code, _PERIODIC) & (period[a] == p))
        k = k[(n_got[a[k]] >= p) & (n_got[b[k]] >= p)]
        ca = _cycles(pts[a[k]], n_got[a[k]], int(p))
        cb = _cycles(pts[b[k]], n_got[b[k]], int(p))
        d = cycle_distance(ca, cb)
        keep[k] = d <= tol * np.maximum(np.maximum(cycle_size(ca), cycle_size(cb)), 1e-12)
    k = np.flatnonzero(np.isin(code, _CLOUD) & (n_got[a] > 0) & (n_got[b] > 0))
    if k.size:
        def centroid(c):
            P = pts[c]
            ok = _valid(P, n_got[c])[..., None]
            return (np.where(ok, P, 0.0).sum(axis=1) / ok.sum(axis=1))[:, None, :]
        ca, cb = centroid(a[k]), centroid(b[k])
        d = np.abs(ca - cb).max(axis=(1, 2))
        keep[k] = d <= tol * np.maximum(np.maximum(cycle_size(ca), cycle_size(cb)), 1e-12)
    return keep


class FloquetRuns:
    """Floquet multipliers of the cycles of one block (:func:`floquet`), many at a time: one
    prepared run (``rockjit.simulate.prepare``) per forcing frequency, phase and period, called
    again with each cycle's amplitude and point, so that a grid's cycles cost their integration
    and not a run's set-up each."""

    def __init__(self, block, integration, n_steps):
        self.block, self.integration, self.n_steps = block, integration, n_steps
        self._runs = {}

    def __call__(self, forcing, phi, point, period):
        from ..single import simulate
        state = (float(point[0]), float(point[1]))
        key = (forcing.omega, float(phi), int(period))
        run = self._runs.get(key)
        if run is None:
            integration = self.integration.replace(periods=int(period), n_steps=self.n_steps,
                                                   qr_every=0, window=None, max_impacts=None)
            run = simulate.prepare(self.block, forcing.replace(phase=phi, r0=None, s0=None),
                                   state, integration=integration, lyapunov=True)
            self._runs[key] = run
        r = run(state=state, alpha=forcing.alpha)
        mu = np.linalg.eigvals(r.extra["tangent"])
        mu = mu[np.argsort(-np.abs(mu))]
        with np.errstate(divide="ignore"):
            lam = np.log(np.abs(mu)) / (period * forcing.period)
        return mu, lam


def floquet(block, forcing, phi, integration, n_steps, point, period):
    """Floquet multipliers of the cycle through ``point`` (``theta, theta'`` at a strobe
    instant of phase ``phi``): the eigenvalues of the tangent over ``period`` periods, saltation
    at every impact (zero when the cycle passes through rest). ``integration`` gives the
    overturning threshold and the Zeno cut-off. Returns ``(mu, lam)`` with
    ``lam = ln|mu| / (period T)``, sorted decreasing."""
    return FloquetRuns(block, integration, n_steps)(forcing, phi, point, period)


def attractor_distance(x, y, floor=1e-12):
    """How far apart two attractors are, relative to their size; ``None`` when they are not of
    one kind (behaviour and period).

    Rest and rest are 0 apart; two cycles, :func:`~rockjit.grids.cycles.cycle_distance`; two
    clouds (chaotic, aperiodic), the largest difference of their samples' centroids. Sizes are
    the larger attractor's largest ``|theta|, |theta'|``, at least ``floor``. The distance is
    symmetric in ``x`` and ``y``, bit for bit.

    Examples
    --------
    >>> import numpy as np
    >>> from rockjit.grids.identity import Attractor, attractor_distance
    >>> def cycle(*pts):
    ...     return Attractor(id=0, behaviour="symmetric", period=len(pts), points=np.array(pts),
    ...                      fraction=100.0, n_cells=1, lam=np.zeros(2))
    >>> attractor_distance(cycle([0.2, 0.1]), cycle([0.1, 0.1]))
    0.5
    >>> attractor_distance(cycle([0.2, 0.1]), cycle([0.2, 0.1], [-0.2, -0.1])) is None
    True
    """
    if x.behaviour != y.behaviour or x.period != y.period:
        return None
    if x.behaviour == "rest":
        return 0.0
    size = max(cycle_size(x.points), cycle_size(y.points), floor)
    if x.period:
        return float(cycle_distance(x.points, y.points) / size)
    return float(np.abs(x.points.mean(axis=0) - y.points.mean(axis=0)).max() / size)


def match_attractors(a, b, tol=MATCH_TOL, floor=1e-12):
    """Pairs ``{id_a: id_b}`` of two lists of attractors whose cycles coincide: same behaviour
    and period, :func:`attractor_distance` within ``tol`` (sizes at least ``floor``); rest
    matches rest, clouds match nothing. Nearest pairs first over all candidates, each attractor
    in one pair at most.

    Within one system (two maps of one basin) ``tol`` is :data:`MATCH_TOL`; across systems
    (the two laws' basins, :func:`attractor_agreement`) the cycles differ and the nearest
    attractor of the same kind is taken (``tol`` of order 1). An erosion profile links one
    amplitude's attractors to the previous one's by another rule on the same distance
    (:mod:`rockjit.basins.erosion`: largest basin first, clouds too).
    """
    cand = []
    for x in a:
        for y in b:
            if x.behaviour != "rest" and not (x.period and x.points.shape == y.points.shape):
                continue
            d = attractor_distance(x, y, floor)
            if d is not None and d <= tol:
                cand.append((d, x.id, y.id))
    pairs, used = {}, set()
    for d, i, j in sorted(cand):
        if i not in pairs and j not in used:
            pairs[i] = j
            used.add(j)
    return pairs


def agreement(label_a, label_b):
    """Percentage of cells where two label arrays (the two laws' behaviour maps of one grid)
    agree.

    Parameters
    ----------
    label_a, label_b : array_like of int
        Two behaviour maps of the same shape (codes into :data:`rockjit.BEHAVIOURS`).

    Returns
    -------
    numpy.float64
        The percent of cells with the same code; NaN for empty maps.

    Examples
    --------
    >>> from rockjit.grids.identity import agreement
    >>> print(agreement([[0, 2], [2, 5]], [[0, 2], [3, 5]]))
    75.0
    """
    a = np.asarray(label_a)
    b = np.asarray(label_b)
    if a.shape != b.shape:
        raise ValueError(f"label arrays differ in shape ({a.shape} vs {b.shape})")
    return 100.0 * np.count_nonzero(a == b) / a.size if a.size else math.nan


#: Across laws, the nearest attractor of the same kind within this many times the orbit's size
#: (at least LAW_FLOOR), see :func:`attractor_agreement`.
LAW_TOL = 1.0
LAW_FLOOR = 0.1


def attractor_agreement(a, b, tol=LAW_TOL, floor=LAW_FLOOR):
    """Agreement of two attractor maps of the same grid (the two laws' basins): the percent of
    cells that reach matching attractors or both overturn, and the matched pairs
    ``{id_a: id_b}``. Two laws are two systems, so their attractors match when they are of the
    same kind (behaviour and period) and nearest to each other, within ``tol`` of the orbit's
    size or ``floor``, whichever is larger (:func:`match_attractors`)."""
    pairs = match_attractors(a.attractors, b.attractors, tol, floor)
    ia, ib = np.asarray(a.attractor), np.asarray(b.attractor)
    lut = np.full(len(a.attractors), -3)
    for i, j in pairs.items():
        lut[i] = j
    mapped = np.where(ia >= 0, lut[np.maximum(ia, 0)] if lut.size else -3, ia)
    same = (mapped == ib) & (ia != UNRESOLVED_ID)
    return dict(percent=100.0 * np.mean(same) if same.size else math.nan,
                pairs={int(i): int(j) for i, j in pairs.items()})


def cycles_differ(pts_a, pts_b, period, tol=MATCH_TOL):
    """Cell by cell, whether two runs' settled cycles differ (``period > 0`` cells): the last
    ``p`` finite samples of ``pts_a[i]`` and ``pts_b[i]`` (shape ``(n, m, 2)``, nan-padded)
    further apart than ``tol`` of the orbit's size under every cyclic shift."""
    period = np.asarray(period)
    out = np.zeros(period.size, dtype=bool)
    ga = np.count_nonzero(np.isfinite(pts_a[..., 0]), axis=1)
    gb = np.count_nonzero(np.isfinite(pts_b[..., 0]), axis=1)
    for p in np.unique(period[period > 0]):
        k = np.flatnonzero((period == p) & (ga >= p) & (gb >= p))
        ca = _cycles(pts_a[k], ga[k], int(p))
        cb = _cycles(pts_b[k], gb[k], int(p))
        size = np.maximum(np.maximum(cycle_size(ca), cycle_size(cb)), 1e-12)
        out[k] = cycle_distance(ca, cb) > tol * size
    return out
