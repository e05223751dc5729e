"""Erosion profiles: basins along a forcing parameter, their integrity, and their attractors
continued from one amplitude to the next (global continuation, as in Attractors.jl).

:func:`erosion` plans one grid of every basin's cells (``n_alpha`` stacked basins, each on
the same ``(theta0, theta0')`` lattice at the same forcing phase), so the whole profile runs as
one computation: chunk by chunk with progress, resumable from a chunk store, on Dask when asked.
and then, at each amplitude, identifies the attractors (:func:`rockjit.grids.identity.identify`)
and measures the basin (:mod:`rockjit.measures`: GIM, IF, basin entropy), and links each
amplitude's attractors to the previous amplitude's (same behaviour and period, cycles within
``cont_tol`` of the orbit's size, the nearest one): a *branch* is an attractor followed across
amplitudes, and its basin fraction against the amplitude is the stacked panel of the profile.

The erosion profile of Lenci and Rega is GIM and IF against the forcing; the study's claim that
Mao's law "reduces the domain of safe bounded motion" is measured by comparing the two laws'.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._engine import kernel
from ..excitation import check_acceleration
from ..grids import basin_grid as grid_basin
from ..grids import plan as gp
from ..entry import entry_point
from ..grids import runner
from ..settings import Integration
from ..validate import real
from .. import measures as M
from ..grids.identity import FloquetRuns, attractor_distance, identify

__all__ = ["LINK_TOL", "ErosionResult", "erosion"]

#: Continuation tolerance from one amplitude to the next, relative to the orbit's size: an
#: amplitude step of a few hundredths moves a cycle by up to a fifth of its size, while two
#: distinct attractors of one kind lie about their own size apart; the nearest one is taken.
LINK_TOL = 0.35


@dataclass(frozen=True)
class ErosionPlan:
    """The stacked basins of an erosion profile: a :class:`rockjit.grids.plan.GridPlan` of all
    cells (amplitude-major) and the amplitudes."""

    grid_plan: gp.GridPlan
    alpha: np.ndarray
    grid: int
    floquet: bool
    cont_tol: float


@dataclass
class ErosionResult:
    """An erosion profile: per amplitude, the basin's integrity and each branch's fraction.

    Attributes
    ----------
    alpha : ndarray, shape (na,)
    GIM, IF : ndarray, shape (na,)
        Global integrity measure and integrity factor of each basin (rockjit.measures).
    basin_entropy, boundary_basin_entropy : ndarray, shape (na,)
    overturn : ndarray, shape (na,)
        Percent of cells that overturn.
    branches : list of dict
        Each attractor continued across amplitudes: ``id``, ``behaviour``, ``period``,
        ``alpha`` (first, last), and ``fraction`` (percent of cells, an array over all
        amplitudes, 0 where absent).
    attractor : ndarray of int, shape (na, grid, grid)
        The attractor map of each basin, in branch ids (-1 overturn, -2 unresolved).
    label : ndarray of int, shape (na, grid, grid)
        The behaviour map of each basin.
    theta0, dtheta0 : ndarray, shape (grid,)
    block : Block
    forcing : Harmonic
        The excitation (without the amplitude the profile sweeps).
    settings : dict

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic
    >>> prof = rockjit.erosion(Block(hb=1), Harmonic(omega=1.3), [0.6, 0.7], grid=10)
    >>> prof.GIM.tolist(), prof.attractor.shape
    ([0.54, 0.49], (2, 10, 10))
    >>> [(b["behaviour"], b["period"]) for b in prof.branches]
    [('symmetric', 1), ('symmetric', 1), ('asymmetric', 1)]
    """

    alpha: np.ndarray
    GIM: np.ndarray
    IF: np.ndarray
    basin_entropy: np.ndarray
    boundary_basin_entropy: np.ndarray
    overturn: np.ndarray
    branches: list
    attractor: np.ndarray
    label: np.ndarray
    theta0: np.ndarray
    dtheta0: np.ndarray
    block: object
    forcing: object = None
    settings: dict = field(default_factory=dict)

    def __repr__(self):
        from ..reprs import text
        return text(self)

    def fractions(self):
        """``(n_branches, na)``: each branch's percent of cells at each amplitude."""
        return np.array([b["fraction"] for b in self.branches]).reshape(-1, self.alpha.size)

    def arrays(self, suffix=""):
        """The profile's arrays by name (each name + ``suffix``), for an ``.npz``."""
        d = dict(GIM=self.GIM, IF=self.IF, fractions=self.fractions(), overturn=self.overturn,
                 basin_entropy=self.basin_entropy, attractor=self.attractor, label=self.label)
        return {k + suffix: v for k, v in d.items()}

    def to_summary(self):
        """JSON-ready: the profile's arrays and the branches."""
        return dict(alpha=self.alpha, GIM=self.GIM, IF=self.IF,
                    basin_entropy=self.basin_entropy,
                    boundary_basin_entropy=self.boundary_basin_entropy,
                    overturn_percent=self.overturn,
                    branches=[{k: v for k, v in b.items()} for b in self.branches],
                    law=self.block.law, restitution=self.block.restitution,
                    settings=self.settings)


    def to_xarray(self):
        """The profile as a labelled ``xarray.Dataset`` (needs ``pip install
        rockjit[xarray]``).

        Returns
        -------
        xarray.Dataset
            Coordinates ``alpha``, ``theta0``, ``dtheta0`` (with ``units`` and ``long_name``)
            and ``branch`` (the branch ids); variables ``GIM``, ``IF``, ``basin_entropy``,
            ``boundary_basin_entropy``, ``overturn`` (over ``alpha``), ``label`` and
            ``attractor`` (``alpha, theta0, dtheta0``, their codes named in CF
            ``flag_values``/``flag_meanings``), ``fraction`` (``branch, alpha``: :meth:`fractions`),
            ``branch_behaviour`` and ``branch_period``; attributes: the block, the excitation
            and the settings as numbers and strings, so that ``ds.to_netcdf(path)`` writes it.

        Raises
        ------
        ImportError
            Without xarray.

        Examples
        --------
        >>> import rockjit
        >>> from rockjit import Block, Harmonic
        >>> prof = rockjit.erosion(Block(hb=1), Harmonic(omega=1.3), [0.6, 0.7], grid=10)
        >>> ds = prof.to_xarray()
        >>> ds.GIM.sel(alpha=0.7).item(), ds.attractor.dims
        (0.49, ('alpha', 'theta0', 'dtheta0'))
        >>> ds.branch_behaviour.values.tolist()
        ['symmetric', 'symmetric', 'asymmetric']
        """
        from ..result import BEHAVIOURS
        from ..storage.labelled import erosion_dataset
        return erosion_dataset(self, BEHAVIOURS)

def _link(prev, cur, tol, floor):
    """``{id_cur: id_prev}``: each current attractor, largest basin first, to the nearest
    previous one not yet taken of the same behaviour and period whose
    :func:`~rockjit.grids.identity.attractor_distance` is within ``tol`` (rest to rest; clouds
    by their centroids); the size is at least ``floor`` (a small orbit moves by more than its
    own size from one amplitude to the next, while staying far from any other).

    Not :func:`~rockjit.grids.identity.match_attractors`, which pairs the nearest candidates
    first over all pairs and leaves clouds unmatched: along a profile the largest basin claims
    its predecessor first, and a chaotic attractor is followed too."""
    links = {}
    taken = set()
    for a in sorted(cur, key=lambda x: -x.n_cells):
        best, dist = None, math.inf
        for b in prev:
            if b.id in taken:
                continue
            d = attractor_distance(a, b, floor)
            if d is not None and d <= tol and d < dist:
                best, dist = b.id, d
        if best is not None:
            links[a.id] = best
            taken.add(best)
    return links


def run(plan: ErosionPlan, execution=None):
    """Execute an :class:`ErosionPlan`; returns an :class:`ErosionResult`."""
    from ..settings import Execution
    execution = Execution() if execution is None else execution
    cont_tol = plan.cont_tol
    g_plan = plan.grid_plan
    out = runner.run_grid(g_plan.y0s, g_plan.pars, g_plan.ipar, g_plan.cpar, tangent=False,
                          n_pts=g_plan.n_pts, n_imp_pts=0,
                          label=gp.progress_label("erosion", g_plan.block, g_plan.forcing),
                          execution=execution)
    r = kernel.grid_results(out)
    na, g = plan.alpha.size, plan.grid
    n = g * g
    label, period = r["label"], r["period"]
    th, dth = g_plan.axes["theta0"], g_plan.axes["dtheta0"]
    runs = FloquetRuns(g_plan.block,
                       Integration(theta_over=g_plan.settings["theta_over"],
                                   rest_speed=g_plan.settings["rest_speed"]),
                       g_plan.settings["n_steps"])
    # the size below which orbits count as small: a tenth of the sampled region's half-width
    floor = 0.1 * max(th[-1] - th[0], dth[-1] - dth[0]) / 2 or 0.1
    gim, if_, sb, sbb, over = (np.zeros(na) for _ in range(5))
    amap = np.empty((na, g, g), dtype=np.int64)
    branches = []      # dicts, by branch id
    prev, prev_branch = [], {}
    for k in range(na):
        sl = slice(k * n, (k + 1) * n)
        ids, found = identify(label[sl], period[sl], out["pts"][sl], out["n_got"][sl])
        forcing = g_plan.forcing.replace(alpha=float(plan.alpha[k]))
        if plan.floquet:
            for a in found:
                if a.period:
                    a.multipliers, a.lam = runs(forcing, g_plan.phi, a.points[0], a.period)
        links = _link(prev, found, cont_tol, floor)
        branch_of = {}
        for a in found:
            if a.id in links:
                bid = prev_branch[links[a.id]]
            else:
                bid = len(branches)
                branches.append(dict(id=bid, behaviour=a.behaviour, period=a.period,
                                     alpha=[float(plan.alpha[k])] * 2,
                                     fraction=np.zeros(na), points=a.points.tolist(),
                                     multipliers=None))
            branch_of[a.id] = bid
            br = branches[bid]
            br["alpha"][1] = float(plan.alpha[k])
            br["fraction"][k] = a.fraction
            if a.multipliers is not None and br["multipliers"] is None:
                br["multipliers"] = [[float(np.real(m)), float(np.imag(m))]
                                     for m in a.multipliers]
        ids2 = ids.reshape(g, g)
        lut = np.array([branch_of[a.id] for a in found] or [-2], dtype=np.int64)
        amap[k] = np.where(ids2 >= 0, lut[np.maximum(ids2, 0)], ids2)
        integ = M.integrity(ids2, th, dth)
        ent = M.basin_entropy(ids2, box=min(5, g))
        gim[k], if_[k], sb[k], sbb[k] = integ.GIM, integ.IF, ent.Sb, ent.Sbb
        over[k] = 100.0 * np.mean(ids2 == -1)
        prev, prev_branch = found, branch_of
    settings = dict(g_plan.settings, grid=g, alpha_step=float(plan.alpha[1] - plan.alpha[0])
                    if na > 1 else 0.0, cont_tol=cont_tol)
    return ErosionResult(alpha=plan.alpha, GIM=gim, IF=if_, basin_entropy=sb,
                         boundary_basin_entropy=sbb, overturn=over, branches=branches,
                         attractor=amap, label=label.reshape(na, g, g), theta0=th, dtheta0=dth,
                         block=g_plan.block, forcing=g_plan.forcing.replace(alpha=None),
                         settings=settings)


@entry_point(run)
def erosion(block, forcing, alphas, grid=100, *, integration=None, classification=None,
            floquet=True, cont_tol=LINK_TOL, execution=None) -> ErosionResult:
    """Erosion profile of the basin over ``(theta0, theta0')`` along the forcing amplitude.

    Parameters
    ----------
    block : Block
        The block.
    forcing : Harmonic
        The excitation with its ``omega`` and no ``alpha`` (the profile's own); its phase is
        every cell's (default ``(r0, s0) = (0, 1)``).
    alphas : array_like, shape (na,)
        The amplitudes, increasing (:func:`rockjit.alpha_grid` makes an evenly spaced range).
    grid : int or Lattice
        Each basin's lattice (as in :func:`rockjit.basin`).
    integration, classification, execution :
        As in :func:`rockjit.sweep`; the whole stack of basins is one computation.
    floquet : bool
        Compute the Floquet multipliers of every periodic attractor.
    cont_tol : float
        Continuation tolerance of the attractors from one amplitude to the next, relative to
        the orbit's size.

    Returns
    -------
    ErosionResult
        GIM, IF and basin entropy per amplitude, and the attractors as branches with their
        basin fractions.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic
    >>> prof = rockjit.erosion(Block(hb=1), Harmonic(omega=1.3), [0.6, 0.7], grid=10)
    >>> prof.GIM.shape
    (2,)
    """
    forcing = gp.harmonic(forcing, "omega", "-alpha", why="an erosion profile")
    alphas = gp.alphas_array(alphas)
    if np.any(np.diff(alphas) <= 0):
        raise ValueError("alphas must increase")
    check_acceleration(float(alphas[-1]), forcing.omega)
    cont_tol = real("cont_tol", cont_tol, 0.0, None, lo_open=True)
    integration, classification, execution = gp.objects(block, integration, classification,
                                                        execution)
    classification = classification.replace(attractors=True, uncertainty=None)
    lat = grid_basin.lattice(grid)
    if lat.grid < 2:
        raise ValueError(f"grid must be >= 2 for an erosion profile: its integrity measures need "
                         f"a two-dimensional lattice (got {lat.grid})")
    # the whole stack's memory first, before any basin's arrays are made
    first_forcing = forcing.replace(alpha=float(alphas[0]))
    _, _, _, settings = gp.common(block, first_forcing, 0.0, integration, classification)
    gp.grid_memory(f"grid = {lat.grid} at {alphas.size} amplitudes",
                   float(lat.cells) * alphas.size, settings, execution, settings["pmax"])
    first = grid_basin.basin.plan(block, first_forcing, lat, integration=integration,
                                  classification=classification, execution=execution)
    n = first.y0s.shape[0]
    y0s = np.tile(first.y0s, (alphas.size, 1))
    pars = np.tile(first.pars, (alphas.size, 1))
    kernel.vary(pars, alpha=np.repeat(alphas, n))
    g_plan = gp.GridPlan(kind="erosion", block=block, forcing=first.forcing, y0s=y0s,
                         pars=pars, ipar=first.ipar, cpar=first.cpar, tangent=False,
                         n_pts=first.n_pts, n_imp_pts=0, axes=dict(alpha=alphas, **first.axes),
                         shape=(alphas.size,) + first.shape, settings=dict(first.settings),
                         memory_bytes=first.memory_bytes * alphas.size, attractors=True,
                         phi=first.phi)
    return ErosionPlan(grid_plan=g_plan, alpha=alphas, grid=first.shape[0],
                       floquet=bool(floquet), cont_tol=cont_tol)
