"""What every grid computation shares: its validated plan, its memory check, and the step from
the engine's arrays to a result with its attractors identified.

A grid entry point (:mod:`.sweep_grid`, :mod:`.basin_grid`, :mod:`.plane_grid`, and the erosion profile and fate
ensembles of :mod:`rockjit.basins`) checks its inputs together into a :class:`GridPlan` of
packed kernel inputs; :func:`run` executes a plan through the grid runner (chunk by chunk, in
this process or on a Dask cluster, resumable from a chunk store: :mod:`.runner`) and wraps the
arrays into a result (:mod:`rockjit.result`).

Cells are classified by the behaviour rules of docs/theory/behaviours.md on the stroboscopic
samples over the asymptotic window or, with early stopping (on by default), on the stretch that
showed a bounded run had settled: a run stops as soon as its last ``settle_reps * p`` periods
repeat to ``settle_tol`` (much tighter than ``tol``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numba
import numpy as np

from .._engine import kernel
from ..excitation import ALPHA_MAX, OMEGA_RANGE, Harmonic, check_acceleration
from ..model import Block
from ..result import BasinResult, PlaneResult, SweepResult
from ..settings import Classification, Execution, Integration
from ..single import check_step, settings_for

from ..validate import integer, memory, pair, real
from . import runner
from .identity import (FloquetRuns, cycles_differ, identify, identify_along,
                       match_attractors)

__all__ = ["GRID_N", "MAX_CELLS", "GridPlan", "alpha_count", "alpha_grid", "common",
           "exponents", "forcing_axes", "grid_memory", "progress_label", "run", "uncertain_cells"]

#: Steps per period of sweeps, basins and planes: they need labels and lambda_max, not 1e-10
#: event times. On the study's four basins and its 501-amplitude sweep, N = 64 gives the labels
#: of N = 256 in every cell (benchmarks/results/grids.md). Raised like the single runs' default
#: when the forcing is slow or the damping strong.
GRID_N = 64

#: Largest number of cells of one grid (a bound for the integers; the memory check refuses
#: large grids first, with the memory they would need).
MAX_CELLS = 10**18


@dataclass(frozen=True)
class GridPlan:
    """A validated grid computation: packed kernel inputs and what the result needs."""

    kind: str                 # "sweep", "basin", "plane", "erosion" or "fate"
    block: Block
    forcing: Harmonic         # as given (without what the grid sweeps)
    y0s: np.ndarray           # (n, 4) initial states
    pars: np.ndarray          # (n, N_PAR) parameter rows
    ipar: np.ndarray
    cpar: np.ndarray
    tangent: bool
    n_pts: int
    n_imp_pts: int
    axes: dict                # the grid's axes, by name
    shape: tuple              # the result arrays' shape
    settings: dict = field(default_factory=dict)
    memory_bytes: float = 0.0
    attractors: bool = False  # identify the attractors (rockjit.grids.identity)
    phi: float = 0.0          # the forcing phase (basins: of every cell)
    uncertainty: float | None = None  # flag the cells whose outcome moves with eps


def objects(block, integration, classification, execution):
    """The settings objects of a grid, defaults filled in, each checked to be what it says."""
    if not isinstance(block, Block):
        raise ValueError(f"block must be a rockjit.Block (got {type(block).__name__})")
    integration = Integration() if integration is None else integration
    classification = Classification() if classification is None else classification
    execution = Execution() if execution is None else execution
    for name, obj, cls in (("integration", integration, Integration),
                           ("classification", classification, Classification),
                           ("execution", execution, Execution)):
        if not isinstance(obj, cls):
            raise ValueError(f"{name} must be a rockjit.{cls.__name__} "
                             f"(got {type(obj).__name__})")
    return integration, classification, execution


def harmonic(forcing, *names, why):
    """The grid's excitation: a :class:`Harmonic` with ``names`` given and the ``-names`` left
    out (the grid sweeps those)."""
    forcing = Harmonic() if forcing is None else forcing
    if not isinstance(forcing, Harmonic):
        raise ValueError(f"forcing must be a rockjit.Harmonic (got {type(forcing).__name__})")
    if forcing.embedded:
        raise ValueError(f"{why} runs the closed-form forcing: give Harmonic(..., "
                         f"embedded=False)")
    return forcing.require(*names, why=why)


def common(block, forcing, phi, integration, classification):
    """Settings shared by every grid, checked for this block and forcing (the step's
    stability) and packed: ``(par, ipar, cpar, settings)``. ``forcing`` has the grid's first
    ``alpha`` and ``omega``."""
    n_steps, w0, max_impacts = settings_for(block, forcing, integration, GRID_N)
    check_step(forcing.period, n_steps, "closed", 1.0, block.xi)
    cl = classification
    par = kernel.pack(block, forcing, phi, integration, n_steps, cl.settle_tol)
    ipar = kernel.settings(n_steps, integration.periods, max_impacts, w0,
                           settle_reps=cl.settle_reps if cl.early_stop else 0, pmax=cl.pmax,
                           stop_at_overturn=integration.stop_at_overturn,
                           h=forcing.period / n_steps, xi=block.xi)
    cpar = kernel.classification_vector(cl)
    settings = dict(periods=integration.periods, n_steps=n_steps, window=w0,
                    early_stop=cl.early_stop, tol=cl.tol, pmax=cl.pmax, lam_tol=cl.lam_tol,
                    settle_tol=cl.settle_tol, settle_reps=cl.settle_reps,
                    max_impacts=max_impacts, stop_at_overturn=integration.stop_at_overturn,
                    theta_over=integration.theta_over, rest_speed=integration.rest_speed,
                    law=block.law, restitution=block.restitution)
    return par, ipar, cpar, settings


def grid_memory(what, n_cells, settings, execution, n_pts=0, n_imp_pts=0, lyapunov=False,
                copies=1):
    """Refuse a grid whose arrays would not fit (``what`` names the parameter that sized it, in
    the message); returns the bytes it needs. ``copies``: outputs held at once (2 for the
    uncertain-cell test, whose second run's outputs sit beside the first's). In this process
    a chunk's pieces are held until the chunk is complete, beside the pieces running
    (:func:`rockjit.grids.runner.pieces`): both are counted."""
    n = int(min(n_cells, MAX_CELLS))
    threads = execution.threads or numba.config.NUMBA_NUM_THREADS
    chunk = execution.chunk or kernel.default_chunk(n)
    if execution.client is None and execution.scheduler is None:
        chunk = chunk + threads * runner.PIECE_MAX
    nbytes = copies * kernel.grid_bytes(n_cells, settings["periods"], settings["n_steps"], n_pts,
                                        n_imp_pts, bool(lyapunov), chunk, threads)
    memory(f"{what} ({n_cells:.4g} cells) over periods = {settings['periods']:.4g}", nbytes)
    return nbytes


def alpha_count(alpha_range, alpha_step):
    """Validated ``(a0, a1, step, count)`` of ``alpha_range`` at ``alpha_step`` (no array
    made: the count may be too large for memory, and is checked first)."""
    a0, a1 = pair("alpha_range", alpha_range, 0.0, ALPHA_MAX)
    step = real("alpha_step", alpha_step, 0.0, None, lo_open=True)
    count = (a1 - a0) / step + 1e-9
    if not count < 2.0**53:  # also inf: a step of 5e-324
        raise ValueError(f"alpha_step = {step:g} over alpha_range ({a0:g}, {a1:g}) would make "
                         f"{count:.3g} amplitudes; give a larger alpha_step")
    return a0, a1, step, math.floor(count) + 1


def forcing_axes(alpha_range, omega_range, grid, max_side):
    """Validated ``(a0, a1, na), (w0, w1, nw)`` of an (alpha, omega) grid: the ranges (ends
    included, ``0 <= a0 <= a1 <= ALPHA_MAX``, ``w0 <= w1`` in ``OMEGA_RANGE``), the points
    ``grid = (na, nw)`` along each, in ``[1, max_side]``, and the largest forcing's
    acceleration (:func:`rockjit.excitation.check_acceleration`). No array is made: the grid
    may be too large for memory, and is checked by the caller."""
    a0, a1 = pair("alpha_range", alpha_range, 0.0, ALPHA_MAX)
    w0, w1 = pair("omega_range", omega_range, *OMEGA_RANGE)
    try:
        na, nw = grid
    except (TypeError, ValueError):
        raise ValueError(f"grid must be two integers (na, nw) (got {grid!r})") from None
    na = integer("grid[0]", na, 1, max_side)
    nw = integer("grid[1]", nw, 1, max_side)
    check_acceleration(a1, w1)
    return (a0, a1, na), (w0, w1, nw)


def alpha_grid(alpha_range, alpha_step):
    """The amplitudes ``alpha_range[0], alpha_range[0] + step, ..., alpha_range[1]`` (end
    included), for a sweep or an erosion profile.

    Parameters
    ----------
    alpha_range : pair of float
        First and last amplitude, ``0 <= a0 <= a1``.
    alpha_step : float
        The step, ``> 0``; the last amplitude is kept when the range is a whole number of steps
        (to ``1e-9`` of a step).

    Returns
    -------
    ndarray
        The amplitudes.

    Examples
    --------
    >>> import rockjit
    >>> rockjit.alpha_grid((0.5, 0.6), 0.05)
    array([0.5 , 0.55, 0.6 ])
    """
    a0, _, step, n = alpha_count(alpha_range, alpha_step)
    memory(f"alpha_step = {step:g} over alpha_range", 8.0 * n)
    return a0 + step * np.arange(n)


def alphas_array(alphas):
    """A sweep's amplitudes, checked: a non-empty 1-D sequence of numbers in
    ``[0, ALPHA_MAX]``."""
    if isinstance(alphas, (str, bytes)) or np.iscomplexobj(alphas):
        raise ValueError(f"alphas must be a sequence of real numbers (got {alphas!r})")
    try:
        a = np.atleast_1d(np.asarray(alphas))
    except (TypeError, ValueError):
        raise ValueError(f"alphas must be a sequence of numbers (got {alphas!r})") from None
    if a.dtype.kind not in "iuf":
        raise ValueError(f"alphas must be a sequence of real numbers (got {alphas!r})")
    a = a.astype(float)
    if a.ndim != 1 or a.size == 0:
        raise ValueError("alphas must be a non-empty 1-D sequence")
    if not np.all(np.isfinite(a)) or np.any(a < 0) or np.any(a > ALPHA_MAX):
        raise ValueError(f"alphas must be finite and in [0, {ALPHA_MAX:g}]")
    return a


def n_points(name, value, default):
    """A count of samples kept per cell, ``>= 1`` (``None``: ``default``)."""
    return default if value is None else integer(name, value, 1, 10**6)


#: The excitation's fields each kind of grid holds fixed (the others it sweeps).
FIXED = {"sweep": ("omega",), "basin": ("alpha", "omega"), "plane": (),
         "erosion": ("omega",), "fate": ("alpha", "omega")}


def progress_label(kind, block, forcing=None):
    """What a grid's progress counts, as its description: the kind of grid, the block's
    slenderness and law, and the forcing's fixed fields (:data:`FIXED`).

    >>> from rockjit import Block, Harmonic
    >>> progress_label("basin", Block(hb=1), Harmonic(alpha=0.66, omega=1.3))
    'basin hb=1 housner alpha=0.66 omega=1.3'
    >>> progress_label("sweep", Block(hb=2, e=0.8), Harmonic(omega=1.6))
    'sweep hb=2 constant e=0.8 omega=1.6'
    """
    words = [kind, f"hb={block.hb:g}", block.law]
    if block.e is not None:
        words.append(f"e={block.e:g}")
    for name in FIXED.get(kind, ()):
        value = getattr(forcing, name, None)
        if value is not None:
            words.append(f"{name}={value:g}")
    return " ".join(words)


def run(plan: GridPlan, execution=None):
    """Execute a :class:`GridPlan`; returns its :class:`SweepResult`, :class:`BasinResult` or
    :class:`PlaneResult` (``execution``: a :class:`rockjit.Execution`, default in-process with
    all threads)."""
    return _run(plan, execution, progress_label(plan.kind, plan.block, plan.forcing))


def _run(plan, execution, label):
    """:func:`run`, its progress described by ``label``."""
    p = plan
    execution = Execution() if execution is None else execution
    out = runner.run_grid(p.y0s, p.pars, p.ipar, p.cpar, tangent=p.tangent, n_pts=p.n_pts,
                          n_imp_pts=p.n_imp_pts, label=label, execution=execution)
    r = kernel.grid_results(out)
    label = r["label"].reshape(p.shape)
    period = r["period"].reshape(p.shape)
    window = r["lam1"].reshape(p.shape)
    exact = {}
    lam = exponents(p, r, out["pts"], out["n_got"], exact).reshape(p.shape) if p.tangent \
        else window
    common_ = dict(block=p.block, forcing=p.forcing, settings=dict(p.settings), label=label,
                   period=period, t_end=r["t_end"].reshape(p.shape),
                   lambda_window=window if p.tangent else None)
    if p.attractors:
        common_["attractor"], common_["attractors"] = _identify(p, r, out["pts"],
                                                               out["n_got"], exact)
    if p.kind == "sweep":
        result = SweepResult(alpha=p.axes["alpha"], lambda_max=lam, strobe=out["pts"],
                             impact_section=out["imp"], t_overturn=r["t_overturn"],
                             motion=r["motion"], **common_)
    elif p.kind == "basin":
        result = BasinResult(theta0=p.axes["theta0"], dtheta0=p.axes["dtheta0"],
                             lambda_max=lam if p.tangent else None, **common_)
    else:
        result = PlaneResult(alpha=p.axes["alpha"], omega=p.axes["omega"], z0=p.axes["z0"],
                             lambda_max=lam, **common_)
    if p.uncertainty is not None:
        result.uncertain = uncertain_cells(p, result, p.uncertainty, execution=execution)
        result.settings["uncertainty"] = p.uncertainty
    return result


def uncertain_cells(plan, result, eps, *, seed=0, execution=None):
    """Which cells of a grid change outcome when their initial state moves by ``eps``
    (Grebogi, McDonald, Ott & Yorke 1983).

    Each cell's ``(theta0, theta0')`` is moved by ``eps`` times its size (absolute where 0) in
    a seeded random direction and run again with the same plan; a cell is uncertain when the
    moved run reaches another outcome: another behaviour or period, or another attractor (the
    two maps' attractors matched by their cycles, :mod:`rockjit.grids.identity`). Returns a
    boolean array shaped like the labels.
    """
    rng = np.random.default_rng(seed)
    ang = rng.uniform(0.0, 2.0 * np.pi, plan.y0s.shape[0])
    y0s = plan.y0s.copy()
    scale = np.where(np.abs(y0s[:, :2]) > 0, np.abs(y0s[:, :2]), 1.0)
    y0s[:, 0] += eps * scale[:, 0] * np.cos(ang)
    y0s[:, 1] += eps * scale[:, 1] * np.sin(ang)
    if execution is not None and execution.store is not None:
        # the moved grid is another computation: its chunks keep a store of their own
        from pathlib import Path
        execution = execution.replace(store=Path(execution.store) / "uncertainty")
    moved = _run(replace(plan, y0s=y0s, uncertainty=None), execution,
                 progress_label(plan.kind, plan.block, plan.forcing) + " (moved by eps)")
    differ = (np.asarray(result.label) != moved.label) | (np.asarray(result.period) !=
                                                          moved.period)
    if result.attractor is not None and moved.attractor is not None and plan.kind == "basin":
        pairs = match_attractors(result.attractors, moved.attractors)
        lut = np.array([pairs.get(a.id, -3) for a in result.attractors] or [-3])
        ids = np.asarray(result.attractor)
        differ |= np.where(ids >= 0, lut[np.maximum(ids, 0)], ids) != moved.attractor
    elif plan.kind == "sweep":  # each cell its own system: its cycle against its own
        same = ~differ
        differ[same] |= cycles_differ(result.strobe[same], moved.strobe[same],
                                      result.period[same])
    return differ


def _cell_forcing(p, cell):
    """``(alpha, omega, phi)`` of a cell: a basin's cells share the plan's forcing; a sweep's
    or a plane's each have their own (read from the cell's parameter row)."""
    if p.kind == "basin":
        return p.forcing.alpha, p.forcing.omega, p.phi
    return kernel.forcing_of(p.pars[cell])


def _floquet_of(runs, alpha, omega, phi, point, period, exact):
    """The multipliers of one cycle (``runs``: a :class:`~rockjit.grids.identity.FloquetRuns`
    of the plan's block), kept in ``exact`` under its exact inputs: a cycle met again with
    bit-identical inputs reuses them, any other is computed anew."""
    point = np.asarray(point, dtype=float)
    key = (float(alpha), float(omega), float(phi), point.tobytes(), int(period))
    if key not in exact:
        exact[key] = runs(Harmonic(alpha=alpha, omega=omega), phi, point, int(period))
    mu, lam = exact[key]
    return mu.copy(), lam.copy()


def _floquet_runs(p):
    """The Floquet runs of a plan's cycles: its block, its overturning threshold and Zeno
    cut-off, its steps per period."""
    integration = Integration(theta_over=p.settings["theta_over"],
                              rest_speed=p.settings["rest_speed"])
    return FloquetRuns(p.block, integration, p.settings["n_steps"])


def exponents(p, r, pts, n_got, exact=None):
    """``lambda_max`` of each cell (flat): the Floquet exponent ``ln|mu1| / (pT)`` where the
    cell settled on a periodic orbit, the finite-window estimate ``lam1`` elsewhere.

    A cell is periodic when its label is symmetric, asymmetric or multiperiodic with a period
    ``p`` and it kept at least ``p`` samples at ``t = kT``: its cycle point
    ``pts[cell, n_got - p]`` (the first of its last ``p``) starts a run of ``p`` periods with
    tangent vectors and no renormalisation, saltation at every impact
    (:func:`rockjit.grids.identity.floquet`), whose tangent is the monodromy; through a rest
    phase the monodromy is zero and the exponent ``-inf``. On a periodic orbit the window's
    QR average converges to this value only as the window grows, slowly and oscillating where
    the multipliers are a complex pair (docs/theory/exponents.md); the exact value does not
    depend on when the run stopped. Every cell is its own computation (a sweep's or a plane's
    cells are each their own system); ``exact`` collects the multipliers by their exact inputs
    so that :func:`_identify` reuses them for an attractor whose cycle point is bit-identical.
    """
    from ..result import ASYMMETRIC, MULTIPERIODIC, SYMMETRIC
    exact = {} if exact is None else exact
    lam = np.array(r["lam1"], dtype=float, copy=True)
    label, period = r["label"], r["period"]
    periodic = np.isin(label, (SYMMETRIC, ASYMMETRIC, MULTIPERIODIC)) & (period > 0) & \
        (n_got >= period)
    runs = _floquet_runs(p)
    for cell in np.flatnonzero(periodic):
        per = int(period[cell])
        alpha, omega, phi = _cell_forcing(p, cell)
        _, lam_c = _floquet_of(runs, alpha, omega, phi, pts[cell, n_got[cell] - per], per,
                               exact)
        lam[cell] = lam_c[0]
    return lam


def _identify(p, r, pts, n_got, exact=None):
    """Attractor ids (shaped like the labels) and attractors of a plan's cells, with the
    Floquet multipliers of the periodic ones (:mod:`rockjit.grids.identity`; those of a
    cycle already computed by :func:`exponents` with bit-identical inputs are reused)."""
    exact = {} if exact is None else exact
    label, period = r["label"], r["period"]
    lam = np.column_stack([r["lam1"], r["lam2"]]) if p.tangent else None
    runs = _floquet_runs(p)
    if p.kind == "basin":
        ids, found = identify(label, period, pts, n_got, lam)
        forcing = {a.id: (p.forcing.alpha, p.forcing.omega, p.phi) for a in found}
    else:
        shape = p.shape if p.kind == "sweep" else p.shape[1:]
        per_state = int(np.prod(shape))
        ids = np.empty(label.size, dtype=np.int64)
        found, forcing = [], {}
        for m in range(label.size // per_state):  # a plane's initial states, one by one
            sl = slice(m * per_state, (m + 1) * per_state)
            ids_m, found_m = identify_along(label[sl], period[sl], pts[sl], n_got[sl], shape,
                                            lam=None if lam is None else lam[sl])
            shift = len(found)
            ids[sl] = np.where(ids_m >= 0, ids_m + shift, ids_m)
            for a in found_m:
                a.id += shift
                cell = sl.start + a.cell
                a.cell = cell
                a.extent = (a.extent[0] + sl.start, a.extent[1] + sl.start)
                forcing[a.id] = kernel.forcing_of(p.pars[cell])
            found += found_m
    for a in found:
        if a.period:
            alpha, omega, phi = forcing[a.id]
            a.multipliers, a.lam = _floquet_of(runs, alpha, omega, phi, a.points[0], a.period,
                                               exact)
    return ids.reshape(p.shape), found
