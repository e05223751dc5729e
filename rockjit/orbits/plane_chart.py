"""The forcing plane with exact boundaries: the brute-force chart of behaviours over
``(alpha, omega)`` (:func:`rockjit.plane`) and the bifurcation curves that cross it, followed
by continuation (:mod:`.curves`) from the bifurcations located along ``alpha`` on a few
``omega`` lines of the chart.

Definitions and choices
-----------------------
Seeds
    On each seed line ``omega = omega_k`` a sweep over the chart's ``alpha_range`` (step
    ``sweep_step``, from the chart's initial state, without exponents) seeds
    :func:`rockjit.orbits.continue_branches`: every branch of its periodic attractors up to
    ``max_period``, followed both ways with its bifurcations located (branch switching on).
    Each located fold, symmetry breaking, period doubling and grazing of period up to
    ``max_period`` seeds a curve, unless a curve of its type and period already crosses that
    line within ``1e-6`` of it (the same curve, reached from another line, or its mirror
    image: mirror orbits bifurcate at the same parameters). The default lines are five,
    evenly spaced inside ``omega_range``.
Curves
    :func:`rockjit.orbits.continue_curve`, to the chart's edges. A seed that cannot be
    followed (a grazing into rest, a corrector that fails at the seed) is kept in ``refused``
    with its reason.
Overturn boundary
    The chart's own: for each ``omega`` column, the smallest ``alpha`` whose cell overturns
    from the chart's initial state (``nan`` where none does); drawn as the boundary of the
    overturning cells.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..entry import entry_point
from ..excitation import Harmonic
from ..grids import plan as gp
from ..grids import plane_grid, sweep_grid
from ..result import BEHAVIOURS
from ..settings import Classification, Execution
from ..validate import boolean, choice, integer, real, real_array
from .arclength import continue_branches
from .curve_types import CURVE_TYPES, CurveSettings
from .curves import chart_ranges, continue_curve
from .shooting import N_ORBIT, check_block, check_n_steps, check_shooting
from .types import ContinuationSettings, OrbitRefused, Shooting

__all__ = ["CHART_GRID", "SEED_LINES", "ChartCurves", "ChartPlan", "ChartResult", "chart", "run"]

#: The chart's default grid ``(NA, NW)``.
CHART_GRID = (200, 200)
#: The default number of seed lines.
SEED_LINES = 5


@dataclass(frozen=True)
class ChartCurves:
    """Which bifurcation curves a chart draws, where they are seeded, how they are followed.

    Parameters
    ----------
    seed_omegas : sequence of float, optional
        The seed lines, inside the chart's ``omega_range``; default
        :data:`~rockjit.orbits.plane_chart.SEED_LINES` lines evenly spaced.
    max_period : int
        Longest period whose bifurcations seed curves, in ``[1, 16]``; default 2.
    types : sequence of str
        The curve types followed (:data:`rockjit.orbits.CURVE_TYPES`), default all.
    sweep_step : float
        The seed sweeps' amplitude step, ``> 0``; default 0.005.
    n_steps : int
        Steps per period of the orbits' runs, default :data:`rockjit.orbits.N_ORBIT`.
    shooting : Shooting, optional
        The orbits' solver, as in :func:`rockjit.orbits.continue_branches`.
    follow : CurveSettings, optional
        How each curve is followed (steps, points, runs, tolerances).

    Examples
    --------
    >>> from rockjit.orbits import ChartCurves
    >>> ChartCurves(max_period=1, types="fold").types
    ('fold',)
    >>> ChartCurves(max_period=0)
    Traceback (most recent call last):
    ...
    ValueError: max_period must be in [1, 16] (got 0)
    """

    seed_omegas: tuple | None = None
    max_period: int = 2
    types: tuple = CURVE_TYPES
    sweep_step: float = 0.005
    n_steps: int = N_ORBIT
    shooting: Shooting | None = None
    follow: CurveSettings = field(default_factory=CurveSettings)

    def __post_init__(self):
        if self.seed_omegas is not None:
            ws = np.atleast_1d(real_array("seed_omegas", self.seed_omegas, "omega values"))
            if ws.ndim != 1 or ws.size == 0:
                raise ValueError(f"seed_omegas must be one or more omega values (got shape "
                                 f"{ws.shape})")
            object.__setattr__(self, "seed_omegas", tuple(float(w) for w in ws))
        object.__setattr__(self, "max_period", integer("max_period", self.max_period, 1, 16))
        object.__setattr__(self, "types", _types(self.types))
        object.__setattr__(self, "sweep_step", real("sweep_step", self.sweep_step, 0.0, None,
                                                     lo_open=True))
        object.__setattr__(self, "n_steps", check_n_steps(self.n_steps, 10**6))
        if self.shooting is not None:
            object.__setattr__(self, "shooting", check_shooting(self.shooting))
        if not isinstance(self.follow, CurveSettings):
            raise ValueError(f"follow must be a rockjit.orbits.CurveSettings (got "
                             f"{type(self.follow).__name__})")


@dataclass(frozen=True)
class ChartPlan:
    """A validated :func:`chart`: the plane's plan and the continuation's inputs, from
    ``chart.plan(...)``; :func:`run` executes it.

    Examples
    --------
    >>> from rockjit import Block
    >>> from rockjit.orbits import chart
    >>> p = chart.plan(Block(hb=1), (0.2, 1.2), (0.8, 3.0))
    >>> p.plane_plan.shape, [round(w, 2) for w in p.seed_omegas]
    ((1, 200, 200), [1.02, 1.46, 1.9, 2.34, 2.78])
    """

    plane_plan: gp.GridPlan
    block: object
    alpha_range: tuple
    omega_range: tuple
    seed_omegas: tuple
    max_period: int
    types: tuple
    sweep_step: float
    state: object
    forcing: Harmonic
    integration: object
    n_steps: int
    shooting: Shooting | None
    settings: CurveSettings


@dataclass
class ChartResult:
    """The chart and its bifurcation curves.

    Attributes
    ----------
    block : Block
    plane : PlaneResult
        The brute-force chart (``plane.label[0, i, j]`` at ``alpha[i]``, ``omega[j]``).
    alpha_range, omega_range : tuple of float
    curves : list of BifurcationCurve
    seeds : list of dict
        Every bifurcation located on the seed lines: ``omega``, ``type``, ``period``,
        ``alpha``, and ``curve`` (the index of the curve through it) or ``skipped`` (why not).
    refused : list of dict
        The seeds that could not be followed, with the reason.
    overturn_onset : ndarray, shape (n_omega,)
        Per ``omega`` column, the smallest ``alpha`` that overturns on the chart.
    phase : float
        The forcing phase of the curves' section (the seed sweeps').
    timing : dict
        ``chart_s`` (the plane), ``seeds_s`` (the seed lines' sweeps and continuations),
        ``curves_s``.

    Examples
    --------
    >>> from rockjit import Block, chart
    >>> from rockjit.orbits import ChartCurves
    >>> res = chart(Block(hb=1), (0.7, 0.95), (1.25, 1.35), grid=(6, 5),
    ...             curves=ChartCurves(seed_omegas=[1.3], types="period_doubling", max_period=1))
    >>> res.label().shape, [s["type"] for s in res.seeds], res.refused
    ((6, 5), ['period_doubling'], [])
    >>> summary, arrays = res.to_summary()
    >>> summary["law"], sorted(arrays)[:3]
    ('housner', ['alpha', 'label', 'names'])
    """

    block: object
    plane: object
    alpha_range: tuple
    omega_range: tuple
    seed_omegas: tuple
    curves: list
    seeds: list
    refused: list
    overturn_onset: np.ndarray
    phase: float
    timing: dict = field(default_factory=dict)

    def __repr__(self):
        from ..reprs import text
        return text(self)

    @property
    def law(self):
        """The block's restitution law."""
        return self.block.law

    def label(self):
        """``(n_alpha, n_omega)``: the behaviour codes of the chart."""
        return np.asarray(self.plane.label)[0]

    def to_xarray(self):
        """The chart's plane as a labelled ``xarray.Dataset``, with the overturn onset (needs
        ``pip install rockjit[xarray]``).

        Returns
        -------
        xarray.Dataset
            :meth:`rockjit.PlaneResult.to_xarray` of ``plane`` with ``overturn_onset``
            over ``omega`` and the attributes ``chart_phase`` (the curves' section phase) and
            ``n_curves``; the curves themselves are in :meth:`to_summary`.

        Raises
        ------
        ImportError
            Without xarray.

        Examples
        --------
        >>> from rockjit import Block, chart
        >>> from rockjit.orbits import ChartCurves
        >>> res = chart(Block(hb=1), (0.7, 0.95), (1.25, 1.35), grid=(6, 5),
        ...             curves=ChartCurves(seed_omegas=[1.3], types="period_doubling",
        ...                                max_period=1))
        >>> ds = res.to_xarray()
        >>> ds.overturn_onset.dims, ds.attrs["kind"], ds.attrs["n_curves"] == len(res.curves)
        (('omega',), 'chart', True)
        """
        from ..storage.labelled import chart_dataset
        return chart_dataset(self)

    def to_summary(self, suffix=""):
        """``(summary, arrays)``: the chart's fractions, the curves (``"curves"``: type,
        period, law, points and the rest of :meth:`BifurcationCurve.to_dict`), the seeds and
        refusals, the timing; arrays ``alpha``, ``omega``, ``label``, ``overturn_onset`` (each
        name with ``suffix``) and per curve ``curve{i}_...``."""
        pl = self.plane
        arrays = {"alpha": np.asarray(pl.alpha), "omega": np.asarray(pl.omega),
                  "names": np.asarray(pl.names, dtype=str),
                  f"label{suffix}": self.label(),
                  f"period{suffix}": np.asarray(pl.period)[0],
                  f"overturn_onset{suffix}": self.overturn_onset}
        summary = dict(law=self.block.law, hb=self.block.hb, restitution=self.block.restitution,
                       alpha_range=list(self.alpha_range), omega_range=list(self.omega_range),
                       grid=[int(pl.alpha.size), int(pl.omega.size)],
                       seed_omegas=list(self.seed_omegas), phase=self.phase,
                       fractions=pl.fractions(), seeds=self.seeds, refused=self.refused,
                       timing=self.timing)
        return summary, arrays


def _seed_lines(omega_range, seed_omegas):
    w0, w1 = omega_range
    if seed_omegas is None:
        return tuple(w0 + (w1 - w0) * (k + 0.5) / SEED_LINES for k in range(SEED_LINES))
    for w in seed_omegas:
        if not w0 <= w <= w1:
            raise ValueError(f"seed_omegas must lie in omega_range [{w0:g}, {w1:g}] "
                             f"(got {w:g}): a seed outside the chart starts no curve on it")
    return seed_omegas


def _types(types):
    if isinstance(types, str):
        types = (types,)
    out = []
    for t in types:
        choice("types", t, CURVE_TYPES)
        out.append(t)
    if not out:
        raise ValueError(f"types must name at least one of {', '.join(CURVE_TYPES)}")
    return tuple(out)


def run(plan: ChartPlan, execution=None) -> ChartResult:
    """Execute a ``ChartPlan`` (``rockjit.chart.plan(...)``): the chart, the seed lines, the
    curves.

    Parameters
    ----------
    plan : ChartPlan
        From ``chart.plan(...)``.
    execution : Execution, optional
        How the chart's grid runs (threads, chunks, Dask, a chunk store, progress); the seed
        sweeps run in this process with its threads.

    Returns
    -------
    ChartResult

    Raises
    ------
    ValueError
        When no bifurcation is located on any seed line: the ranges contain no seed.

    Examples
    --------
    >>> from rockjit import Block, Execution
    >>> from rockjit.orbits import chart, plane_chart
    >>> from rockjit.orbits import ChartCurves
    >>> plan = chart.plan(Block(hb=1), (0.75, 0.8), (1.28, 1.32), grid=(3, 3),
    ...                   curves=ChartCurves(seed_omegas=[1.3], max_period=1))
    >>> res = plane_chart.run(plan, Execution(progress=False))
    >>> [(c.type, c.ends) for c in res.curves]
    [('symmetry_breaking', ('range', 'range'))]
    """
    execution = Execution() if execution is None else execution
    timing = {}
    t0 = time.perf_counter()
    pl = gp.run(plan.plane_plan, execution)
    timing["chart_s"] = time.perf_counter() - t0
    a0, a1 = plan.alpha_range
    t0 = time.perf_counter()
    conts = [_seed_line(plan, w, execution.threads) for w in plan.seed_omegas]
    timing["seeds_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    found = _CurveSeeds(plan)
    for w, cont in zip(plan.seed_omegas, conts):
        found.line(w, cont)
    timing["curves_s"] = time.perf_counter() - t0
    if not found.seeds:
        raise ValueError(
            f"no bifurcation of period <= {plan.max_period} ({', '.join(plan.types)}) is "
            f"located along alpha in [{a0:g}, {a1:g}] at omega = "
            f"{', '.join(f'{w:g}' for w in plan.seed_omegas)}: the chart's ranges contain no "
            f"seed for a curve")
    return ChartResult(block=plan.block, plane=pl, alpha_range=(a0, a1),
                       omega_range=plan.omega_range, seed_omegas=plan.seed_omegas,
                       curves=found.curves, seeds=found.seeds, refused=found.refused,
                       overturn_onset=_overturn_onset(pl),
                       phase=conts[0].phase if conts else 0.0, timing=timing)


def _seed_line(plan, w, threads):
    """The branches and bifurcations along ``alpha`` on the seed line ``omega = w``: a sweep
    over the chart's ``alpha_range`` seeds :func:`continue_branches`."""
    a0, a1 = plan.alpha_range
    forcing = plan.forcing.replace(omega=w)
    sw = sweep_grid.sweep(plan.block, forcing, gp.alpha_grid((a0, a1), plan.sweep_step),
                          plan.state, integration=plan.integration,
                          classification=Classification(attractors=False), lyapunov=False,
                          execution=Execution(threads=threads, progress=False))
    return continue_branches(plan.block, Harmonic(omega=w), (a0, a1), sweep=sw,
                             n_steps=plan.n_steps, shooting=plan.shooting,
                             settings=ContinuationSettings(max_period=plan.max_period))


class _CurveSeeds:
    """The curves followed from the bifurcations located on the seed lines, a record of
    every such seed (``seeds``), and those that could not be followed (``refused``)."""

    def __init__(self, plan):
        self.plan = plan
        self.curves, self.seeds, self.refused = [], [], []

    def line(self, w, cont):
        """Seed curves from the bifurcations of ``cont``, the continuation on ``omega = w``."""
        plan = self.plan
        shooting = Shooting(**{k: cont.settings[k] for k in
                               ("tol", "max_iter", "sym_tol", "graze_tol", "over_tol",
                                "max_impacts_per_period", "theta_over", "rest_speed")})
        for bf in sorted(cont.bifurcations, key=lambda b: (b.period, b.alpha)):
            if bf.type not in plan.types or bf.period > plan.max_period:
                continue
            rec = dict(omega=float(w), type=bf.type, period=int(bf.period),
                       alpha=float(bf.alpha))
            self.seeds.append(rec)
            self.follow(w, cont, bf, shooting, rec)

    def follow(self, w, cont, bf, shooting, rec):
        """Follow the curve through ``bf`` unless it was not located or a curve found before
        crosses ``omega = w`` there; ``rec`` gets the curve's index, or why there is none."""
        if not bf.located:
            rec["skipped"] = "not located (its bracketing solve failed)"
            return
        on = next((i for i, c in enumerate(self.curves) if c.type == bf.type and
                   c.period == bf.period and c.through(w, bf.alpha, bf.cycle)), None)
        if on is not None:
            rec["curve"] = on
            rec["skipped"] = f"on curve {on}"
            return
        plan = self.plan
        try:
            c = continue_curve(plan.block, bf, phase=cont.phase,
                               alpha_range=tuple(plan.alpha_range),
                               omega_range=plan.omega_range, n_steps=plan.n_steps,
                               shooting=shooting, settings=plan.settings)
        except (OrbitRefused, ValueError) as exc:
            rec["skipped"] = "refused"
            self.refused.append(dict(rec, reason=str(exc)))
            return
        rec["curve"] = len(self.curves)
        self.curves.append(c)


def _overturn_onset(pl):
    """Per ``omega`` column of the chart ``pl``, the smallest ``alpha`` whose cell overturns
    (``nan`` where none does)."""
    lab = np.asarray(pl.label)[0]
    over = lab == BEHAVIOURS.index("overturn")
    alphas = np.asarray(pl.alpha)
    return np.array([alphas[np.argmax(over[:, k])] if over[:, k].any() else math.nan
                     for k in range(over.shape[1])])


@entry_point(run)
def chart(block, alpha_range, omega_range, *, grid=CHART_GRID, curves=None, state=None,
          integration=None, classification=None, lyapunov=False,
          execution=None) -> ChartResult:
    """The forcing plane with exact boundaries: the chart of behaviours over ``(alpha,
    omega)`` and the fold, symmetry-breaking, period-doubling and grazing curves across it.

    ``chart.plan(...)`` (same parameters) checks every input and plans the chart's grid
    without running anything; :func:`rockjit.orbits.plane_chart.run` executes a plan.

    Parameters
    ----------
    block : Block
        The block.
    alpha_range, omega_range : pair of float
        The chart, ``start < end`` (``omega > 0``).
    grid : pair of int
        The chart's points ``(NA, NW)`` along ``alpha`` and ``omega``, default
        :data:`~rockjit.orbits.plane_chart.CHART_GRID`.
    curves : ChartCurves, optional
        Which curves, seeded on which ``omega`` lines, followed how; default
        ``ChartCurves()``: every type up to period 2 from five lines.
    state : pair of float, optional
        The initial ``(theta0, theta0')`` of the chart and the seed sweeps, at the study's
        forcing phase; default the study's ``z0``.
    integration, classification : optional
        The chart's and the seed sweeps' runs and classification (:func:`rockjit.plane`).
    lyapunov : bool
        Compute the chart's ``lambda_max`` (it tells chaotic from aperiodic cells; three
        times the chart's cost). Default ``False``.
    execution : Execution, optional
        The chart's threads, chunks, Dask client, chunk store, progress.

    Returns
    -------
    ChartResult

    Raises
    ------
    ValueError
        For bad input, naming the parameter; at run time, when no seed line has a bifurcation
        in ``alpha_range`` (the ranges contain no seed).

    Examples
    --------
    >>> from rockjit import Block
    >>> from rockjit.orbits import ChartCurves, chart
    >>> curves = ChartCurves(seed_omegas=[1.3], max_period=1,
    ...                      types=("symmetry_breaking", "period_doubling"))
    >>> res = chart(Block(hb=1), (0.7, 0.95), (1.25, 1.35), grid=(6, 5), curves=curves)
    >>> [(c.type, c.period, [round(a, 6) for a in c.alpha_at(1.3)]) for c in res.curves]
    [('symmetry_breaking', 1, [0.779798]), ('period_doubling', 1, [0.911511])]
    >>> chart.plan(Block(hb=1), (0.2, 1.2), (0.8, 3.0), curves=ChartCurves(seed_omegas=[3.5]))
    Traceback (most recent call last):
    ...
    ValueError: seed_omegas must lie in omega_range [0.8, 3] (got 3.5): a seed outside the \
chart starts no curve on it
    """
    block = check_block(block)
    a0, a1, w0, w1 = chart_ranges(alpha_range, omega_range)
    curves = ChartCurves() if curves is None else curves
    if not isinstance(curves, ChartCurves):
        raise ValueError(f"curves must be a rockjit.orbits.ChartCurves (got "
                         f"{type(curves).__name__})")
    plane_plan = plane_grid.plane.plan(block, (a0, a1), (w0, w1), grid=grid, state=state,
                                       integration=integration,
                                       classification=classification,
                                       lyapunov=boolean("lyapunov", lyapunov),
                                       execution=execution)
    seed_omegas = _seed_lines((w0, w1), curves.seed_omegas)
    gp.alpha_count((a0, a1), curves.sweep_step)
    integration, _, _ = gp.objects(block, integration, classification, execution)
    return ChartPlan(plane_plan=plane_plan, block=block, alpha_range=(a0, a1),
                     omega_range=(w0, w1), seed_omegas=seed_omegas,
                     max_period=curves.max_period, types=curves.types,
                     sweep_step=curves.sweep_step, state=state,
                     forcing=gp.harmonic(None, "-alpha", "-omega", why="a chart"),
                     integration=integration, n_steps=curves.n_steps,
                     shooting=curves.shooting, settings=curves.follow)
