"""Integrity charts: the safe basin's measures at every forcing ``(alpha, omega)`` of a grid.

Each column of the chart (one frequency, every amplitude) is exactly an erosion profile's grid
(:func:`rockjit.erosion`'s plan: the same cells, the same packed settings), run through the grid
runner chunk by chunk, resumable from a chunk store (one sub-store per column) and on Dask like
every grid; each basin is then reduced at once to its measures (:mod:`rockjit.measures`):
the safe fraction (cells that do not overturn), GIM, IF and the LIM of its largest safe
attractor, and its attractors (:func:`rockjit.grids.identity.identify`). Only those numbers are
kept, so a chart of thousands of basins needs the memory of one column.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._engine import kernel
from .. import measures as M
from ..basins.erosion import erosion
from ..grids.identity import identify
from ..entry import entry_point
from ..grids import plan as gp
from ..grids import runner
from ..grids.basin_grid import lattice as as_lattice
from ..settings import Execution, Lattice
from ..validate import integer

__all__ = ["MAX_LATTICE", "MAX_SIDE", "SafetyPlan", "SafetyResult", "run", "safety"]

#: Most forcings along each side of a chart (every basin is reduced in Python: a million
#: forcings would take hours of that alone).
MAX_SIDE = 1000

#: Most initial states along each side of every basin's lattice.
MAX_LATTICE = 10**5


@dataclass(frozen=True)
class SafetyPlan:
    """A validated chart: its axes, and what each column's erosion plan needs."""

    block: object
    forcing: object
    alpha: np.ndarray
    omega: np.ndarray
    lattice: object
    integration: object
    classification: object


@dataclass
class SafetyResult:
    """An integrity chart over the forcing plane.

    Attributes
    ----------
    alpha : ndarray, shape (na,)
    omega : ndarray, shape (nw,)
    safe : ndarray, shape (na, nw)
        Fraction of the lattice's initial states that do not overturn (basin stability).
    GIM, IF : ndarray, shape (na, nw)
        Global integrity measure and integrity factor of the safe basin
        (:func:`rockjit.measures.integrity`: unresolved cells are not safe).
    LIM : ndarray, shape (na, nw)
        Local integrity measure of the safe attractor with the largest basin (``nan`` where
        there is none).
    n_attractors : ndarray of int, shape (na, nw)
    behaviours : ndarray of str, shape (na, nw)
        The attractors as ``"symmetric p=1, asymmetric p=1"``, largest basin first.
    attractors : list of list of list of dict
        ``attractors[i][j]``: each attractor of the basin at ``alpha[i], omega[j]``:
        ``behaviour``, ``period``, ``fraction`` (percent of cells), ``points`` (its
        stroboscopic points at the forcing's phase) and ``LIM``.
    theta0, dtheta0 : ndarray
        The lattice of every basin.
    block, forcing, settings

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Integration
    >>> ch = rockjit.safety(Block(hb=1), (0.6, 0.7), (1.2, 1.3), grid=(2, 2), lattice=6,
    ...                     integration=Integration(periods=100))
    >>> ch.safe.shape, ch.n_attractors.shape
    ((2, 2), (2, 2))
    """

    alpha: np.ndarray
    omega: np.ndarray
    safe: np.ndarray
    GIM: np.ndarray
    IF: np.ndarray
    LIM: np.ndarray
    n_attractors: np.ndarray
    behaviours: np.ndarray
    attractors: list
    theta0: np.ndarray
    dtheta0: np.ndarray
    block: object
    forcing: object = None
    settings: dict = field(default_factory=dict)

    def __repr__(self):
        from ..reprs import text
        return text(self)

    def column(self, omega):
        """Index of the column at ``omega`` (the nearest frequency of the chart)."""
        return int(np.argmin(np.abs(self.omega - float(omega))))

    def arrays(self, suffix=""):
        """The chart's arrays by name (each name + ``suffix``), for an ``.npz``."""
        d = dict(safe=self.safe, GIM=self.GIM, IF=self.IF, LIM=self.LIM,
                 n_attractors=self.n_attractors, behaviours=self.behaviours.astype(str))
        return {k + suffix: v for k, v in d.items()}

    def to_summary(self):
        """JSON-ready: the chart's arrays, law and settings (the attractors' points left out)."""
        return dict(alpha=self.alpha, omega=self.omega, safe=self.safe, GIM=self.GIM,
                    IF=self.IF, LIM=self.LIM, n_attractors=self.n_attractors,
                    behaviours=self.behaviours.tolist(), law=self.block.law,
                    restitution=self.block.restitution, settings=self.settings)

    def to_xarray(self):
        """The chart as a labelled ``xarray.Dataset`` (needs ``pip install rockjit[xarray]``).

        Returns
        -------
        xarray.Dataset
            Coordinates ``alpha`` and ``omega``; variables ``safe``, ``GIM``, ``IF``, ``LIM``,
            ``n_attractors`` and ``behaviours`` over ``(alpha, omega)``; attributes: the block
            and the settings as numbers and strings, so that ``ds.to_netcdf(path)`` writes it.

        Examples
        --------
        >>> import rockjit
        >>> from rockjit import Block, Integration
        >>> ch = rockjit.safety(Block(hb=1), (0.6, 0.7), (1.2, 1.3), grid=(2, 2), lattice=6,
        ...                     integration=Integration(periods=100))
        >>> ds = ch.to_xarray()
        >>> ds.safe.dims, ds.safe.shape
        (('alpha', 'omega'), (2, 2))
        """
        import xarray as xr
        coords = dict(alpha=("alpha", self.alpha, dict(long_name="forcing amplitude A/R")),
                      omega=("omega", self.omega, dict(long_name="forcing frequency",
                                                       units="1/p")))
        dims = ("alpha", "omega")
        names = dict(safe="fraction of initial states that do not overturn",
                     GIM="global integrity measure", IF="integrity factor",
                     LIM="local integrity measure of the largest safe attractor",
                     n_attractors="number of attractors",
                     behaviours="the attractors, largest basin first")
        data = {k: (dims, np.asarray(getattr(self, k)) if k != "behaviours"
                    else self.behaviours.astype(str), dict(long_name=v))
                for k, v in names.items()}
        attrs = dict(hb=float(self.block.hb), law=str(self.block.law),
                     restitution=float(self.block.restitution), xi=float(self.block.xi))
        for k, v in self.settings.items():
            if isinstance(v, (bool, np.bool_)):
                attrs[k] = int(v)
            elif isinstance(v, (int, float, str)):
                attrs[k] = v
            elif isinstance(v, (list, tuple)) and all(isinstance(x, (int, float)) for x in v):
                attrs[k] = list(v)
        return xr.Dataset(data, coords=coords, attrs=attrs)


def basin_measures(ids, found, theta0, dtheta0):
    """One basin's entries of a chart: ``(safe, GIM, IF, LIM, attractors)`` from its outcome
    ids (``-1`` overturn, ``-2`` unresolved) and its attractors
    (:func:`rockjit.grids.identity.identify`)."""
    points = {a.id: np.asarray(a.points, dtype=float).reshape(-1, 2) for a in found}
    integ = M.integrity(ids, theta0, dtheta0, points=points or None)
    rows = []
    for a in sorted(found, key=lambda x: -x.n_cells):
        rows.append(dict(behaviour=a.behaviour, period=int(a.period or 0),
                         fraction=float(a.fraction), points=points[a.id].tolist(),
                         LIM=float(integ.LIM[a.id])))
    lim = rows[0]["LIM"] if rows else np.nan
    return float(np.mean(ids != M.OVERTURN)), integ.GIM, integ.IF, lim, rows


def run(plan: SafetyPlan, execution=None):
    """Execute a :class:`SafetyPlan`, column by column; returns a :class:`SafetyResult`."""
    execution = Execution() if execution is None else execution
    na, nw = plan.alpha.size, plan.omega.size
    safe, gim, if_, lim = (np.full((na, nw), np.nan) for _ in range(4))
    count = np.zeros((na, nw), dtype=np.int64)
    names = np.empty((na, nw), dtype=object)
    found_all = [[None] * nw for _ in range(na)]
    done, total = 0, na * nw * plan.lattice.cells
    progress = execution.progress
    settings = {}
    for j, w in enumerate(plan.omega):
        ep = erosion.plan(plan.block, plan.forcing.replace(omega=float(w)), plan.alpha,
                          plan.lattice, integration=plan.integration,
                          classification=plan.classification, floquet=False,
                          execution=execution)
        g_plan = ep.grid_plan
        ex = execution
        if execution.store is not None:
            ex = ex.replace(store=Path(execution.store) / f"omega-{j:04d}-of-{nw}")
        if callable(progress):
            ex = ex.replace(progress=lambda d, t, _o=done: progress(_o + d, total))
        label = gp.progress_label("safety", plan.block) + f" omega={w:g} ({j + 1}/{nw})"
        out = runner.run_grid(g_plan.y0s, g_plan.pars, g_plan.ipar, g_plan.cpar, tangent=False,
                              n_pts=g_plan.n_pts, n_imp_pts=0, label=label, execution=ex)
        done += g_plan.y0s.shape[0]
        r = kernel.grid_results(out)
        th, dth = g_plan.axes["theta0"], g_plan.axes["dtheta0"]
        g = ep.grid
        n = g * g
        for i in range(na):
            sl = slice(i * n, (i + 1) * n)
            ids, found = identify(r["label"][sl], r["period"][sl], out["pts"][sl],
                                  out["n_got"][sl])
            s, G, I, L, rows = basin_measures(ids.reshape(g, g), found, th, dth)
            safe[i, j], gim[i, j], if_[i, j], lim[i, j] = s, G, I, L
            count[i, j] = len(rows)
            names[i, j] = ", ".join(_name_row(x) for x in rows) or "none"
            found_all[i][j] = rows
        settings = dict(g_plan.settings, grid=g)
    return SafetyResult(alpha=plan.alpha, omega=plan.omega, safe=safe, GIM=gim, IF=if_,
                        LIM=lim, n_attractors=count, behaviours=names, attractors=found_all,
                        theta0=th, dtheta0=dth, block=plan.block,
                        forcing=plan.forcing, settings=settings)


def _name_row(x):
    if x["behaviour"] in ("rest", "chaotic") or not x["period"]:
        return x["behaviour"]
    return f"{x['behaviour']} p={x['period']}"


@entry_point(run)
def safety(block, alpha_range, omega_range, *, grid=(20, 20), lattice=50, forcing=None,
           integration=None, classification=None, execution=None) -> SafetyResult:
    """Integrity chart: the safe basin's measures at every forcing of an ``(alpha, omega)``
    grid.

    Parameters
    ----------
    block : Block
        The block.
    alpha_range, omega_range : pair of float
        Ranges, ends included: ``0 <= alpha0 <= alpha1`` and ``0 < omega0 <= omega1`` (a range
        of more than one point must have ``start < end``).
    grid : pair of int
        Points ``(na, nw)`` along alpha and omega, each in ``[1, 1000]`` (default 20 20).
    lattice : int or Lattice
        Every basin's initial states: points per side over ``[-1, 1]^2``, in ``[2, 10^5]``
        (default 50), or a :class:`rockjit.Lattice` of at least 2 per side.
    forcing : Harmonic, optional
        The forcing's phase (no ``alpha`` or ``omega``: the chart sweeps both); default
        ``(r0, s0) = (0, 1)``, the basins' and erosion profiles'.
    integration, classification, execution :
        As in :func:`rockjit.sweep`; the chart runs column by column (one frequency, every
        amplitude), each column chunked, with progress, on Dask when asked, resumable from
        ``execution.store`` (a sub-store per column).

    Returns
    -------
    SafetyResult
        ``safe``, ``GIM``, ``IF``, ``LIM``, ``n_attractors`` and ``behaviours`` of shape
        ``(na, nw)``. The column at a frequency ``omega`` holds the values of
        :func:`rockjit.erosion` at that frequency and the same amplitudes and lattice.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Integration
    >>> ch = rockjit.safety(Block(hb=1), (0.6, 0.7), (1.2, 1.3), grid=(2, 2), lattice=6,
    ...                     integration=Integration(periods=100))
    >>> ch.safe.shape, ch.GIM.shape
    ((2, 2), (2, 2))
    """
    integration, classification, execution = gp.objects(block, integration, classification,
                                                        execution)
    forcing = gp.harmonic(forcing, "-alpha", "-omega", why="a safety chart")
    (a0, a1, na), (w0, w1, nw) = gp.forcing_axes(alpha_range, omega_range, grid, MAX_SIDE)
    if na > 1 and not a0 < a1:
        raise ValueError(f"alpha_range must have start < end for {na} amplitudes "
                         f"(got ({a0:g}, {a1:g}))")
    if nw > 1 and not w0 < w1:
        raise ValueError(f"omega_range must have start < end for {nw} frequencies "
                         f"(got ({w0:g}, {w1:g}))")
    lat = as_lattice(lattice if isinstance(lattice, Lattice) else
                     integer("lattice", lattice, 2, MAX_LATTICE))
    if lat.grid < 2:
        raise ValueError(f"lattice must have >= 2 points per side: the integrity measures need "
                         f"a two-dimensional lattice (got {lat.grid})")
    alphas, omegas = np.linspace(a0, a1, na), np.linspace(w0, w1, nw)
    classification = classification.replace(attractors=True, uncertainty=None)
    # every column is checked now (its steps and memory), before any runs
    for w in omegas[[0, -1]]:
        erosion.plan(block, forcing.replace(omega=float(w)), alphas, lat,
                     integration=integration, classification=classification, floquet=False,
                     execution=execution)
    return SafetyPlan(block=block, forcing=forcing, alpha=alphas, omega=omegas, lattice=lat,
                      integration=integration, classification=classification)
