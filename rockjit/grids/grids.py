"""α sweeps (bifurcation diagrams), basins of attraction and parameter planes.

Each grid computation has a plan and a runner. :func:`plan_sweep`, :func:`plan_basin` and
:func:`plan_plane` validate every input (ranges, classification settings, the grid's stability,
the memory it would allocate) into a :class:`GridPlan` of packed kernel inputs; :func:`run`
executes a plan chunk by chunk (progress between chunks, in this process or on a Dask cluster,
resumable from a chunk store, :mod:`rockjit._engine.kernel` and :mod:`rockjit.storage.chunkstore`) and wraps the
arrays into a result (:mod:`rockjit.result`). :func:`sweep`, :func:`basin` and :func:`plane` are
the two steps in one call; the command line calls them separately, so it refuses bad input
before any work, with the library's own messages.

Cells are classified by the behaviour rules of :mod:`rockjit._engine.classify` (SPEC.md §6), on the
stroboscopic samples over the asymptotic window or, with early stopping (on by default), on the
stretch that showed a bounded run had settled: a run stops as soon as its last
``settle_reps * p`` periods repeat to ``settle_tol`` (much tighter than ``tol``), see
:func:`rockjit._engine.integrate.settled_period`. The full-length mode stays available with
``early_stop=False``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from .._engine import integrate as ig
from .._engine import kernel
from . import runner
from ..basins.identity import (cycles_differ, floquet, identify, identify_along,
                         match_attractors)
from .._engine.classify import classify
from ..model import ALPHA_MAX, OMEGA_RANGE, Block
from ..result import (BEHAVIOURS, BasinResult, PlaneResult, SweepResult, fractions)
from ..single import (Z0_STUDY, check_step, check_theta0, forcing_phase, make_block,
                       run_settings)
from ..validate import integer, memory, pair, real

__all__ = ["BEHAVIOURS", "GRID_N", "BasinResult", "GridPlan", "PlaneResult", "SweepResult",
           "alpha_grid", "basin", "classify_result", "fractions", "plan_basin", "plan_plane",
           "plan_sweep", "plane", "run", "sweep"]

#: Steps per period of sweeps, basins and planes: they need labels and lambda_max, not 1e-10
#: event times. On the study's four basins and its 501-amplitude sweep, N = 64 gives the labels
#: of N = 256 in every cell (benchmarks/README.md, "Grid resolution"). Raised like DEFAULT_N
#: when the forcing is slow (MAX_STEP) or the damping strong.
GRID_N = 64

#: Defaults of the classification (documented in rockjit._engine.classify and the README).
TOL = 1e-6
PMAX = 16
LAM_TOL = 1e-2
SETTLE_TOL = 1e-9
SETTLE_REPS = 10

#: Largest number of cells of one grid (a bound for the integers; the memory check refuses
#: large grids first, with the memory they would need).
MAX_CELLS = 10**18


@dataclass(frozen=True)
class GridPlan:
    """A validated grid computation: packed kernel inputs and what the result needs."""

    kind: str                 # "sweep", "basin" or "plane"
    block: Block              # the block at the grid's first point
    y0s: np.ndarray           # (n, 4) initial states
    pars: np.ndarray          # (n, N_PAR) parameter rows
    ipar: np.ndarray
    cpar: np.ndarray
    tangent: bool
    n_pts: int
    n_imp_pts: int
    threads: int | None
    chunk: int | None
    axes: dict                # the grid's axes, by name
    shape: tuple              # the result arrays' shape
    settings: dict = field(default_factory=dict)
    memory_bytes: float = 0.0
    attractors: bool = False  # identify the attractors (rockjit.basins.identity)
    phi: float = 0.0          # the forcing phase (basins: of every cell)
    uncertainty: float | None = None  # flag the cells whose outcome moves with eps
    lanes: int | None = None  # cells per thread in lockstep (rockjit._engine.lanes; same results;
    #                           None: kernel.DEFAULT_LANES)


def _classification(tol, pmax, lam_tol, settle_tol, settle_reps):
    tol = real("tol", tol, 0.0, 1.0, lo_open=True, hi_open=True)
    settle_tol = real("settle_tol", settle_tol, 0.0, tol, lo_open=True)
    pmax = integer("pmax", pmax, 1, 1000)
    settle_reps = integer("settle_reps", settle_reps, 2, 10**6)
    lam_tol = real("lam_tol", lam_tol)
    return tol, pmax, lam_tol, settle_tol, settle_reps


def _grid_common(block, phi, *, periods, n_steps, window, early_stop, tol, pmax, lam_tol,
                 max_impacts, settle_tol, settle_reps, threads, chunk, stop_at_overturn=True):
    """Settings shared by every grid, validated and packed:
    ``(par, ipar, cpar, settings, threads, chunk)``."""
    periods, n_steps, max_impacts, w0 = run_settings(block, periods, n_steps, GRID_N,
                                                     max_impacts, window)
    check_step(block.period, n_steps, "closed", 1.0, block.xi)
    tol, pmax, lam_tol, settle_tol, settle_reps = _classification(tol, pmax, lam_tol,
                                                                  settle_tol, settle_reps)
    if threads is not None:
        threads = integer("threads", threads, 1, numba.config.NUMBA_NUM_THREADS)
    if chunk is not None:
        chunk = integer("chunk", chunk, 1, MAX_CELLS)
    par = kernel.pack(block, phi, n_steps, settle_tol)
    ipar = kernel.settings(n_steps, periods, max_impacts, w0,
                           settle_reps=settle_reps if early_stop else 0, pmax=pmax,
                           stop_at_overturn=stop_at_overturn, h=block.period / n_steps,
                           xi=block.xi)
    cpar = np.zeros(2)
    cpar[kernel.C_TOL] = tol
    cpar[kernel.C_LAMTOL] = lam_tol
    settings = dict(periods=periods, n_steps=n_steps, window=w0, early_stop=bool(early_stop),
                    tol=tol, pmax=pmax, lam_tol=lam_tol, settle_tol=settle_tol,
                    settle_reps=settle_reps, max_impacts=max_impacts,
                    stop_at_overturn=bool(stop_at_overturn))
    return par, ipar, cpar, settings, threads, chunk


def grid_memory(what, n_cells, settings, threads, chunk, n_pts=0, n_imp_pts=0,
                 lyapunov=False):
    """Refuse a grid whose arrays would not fit (``what`` names the parameter that sized it, in
    the message); returns the bytes it needs."""
    nbytes = kernel.grid_bytes(n_cells, settings["periods"], settings["n_steps"], n_pts,
                               n_imp_pts, bool(lyapunov),
                               chunk or kernel.default_chunk(int(min(n_cells, MAX_CELLS))),
                               threads or numba.config.NUMBA_NUM_THREADS)
    memory(f"{what} ({n_cells:.4g} cells)", nbytes)
    return nbytes


def _check_state(z, block):
    """An initial state ``(theta, theta', r, s)`` of a sweep or plane, component by component
    (the forcing's ``r, s`` are checked by :func:`forcing_phase`)."""
    check_theta0(z[0], block, "z0[0] (theta0)")
    real("z0[1] (dtheta0)", z[1], -1e6, 1e6)
    real("z0[2] (r0)", z[2])
    real("z0[3] (s0)", z[3])


def _uncertainty(eps):
    """The relative perturbation of the uncertain-cell test, or None (no test)."""
    return None if eps is None else real("uncertainty", eps, 1e-15, 0.5)


def _n_points(name, value, default):
    return default if value is None else integer(name, value, 1, 10**6)


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


def alpha_grid(alpha_range, alpha_step):
    """``alpha_range[0], alpha_range[0] + step, ..., alpha_range[1]`` (end included)."""
    a0, _, step, n = alpha_count(alpha_range, alpha_step)
    memory(f"alpha_step = {step:g} over alpha_range", 8.0 * n)
    return a0 + step * np.arange(n)


def _alphas(alphas, alpha_range, alpha_step):
    if alphas is not None and alpha_range is not None:
        raise ValueError("give alphas or alpha_range, not both")
    if alphas is None:
        if alpha_range is None:
            raise ValueError("give alphas or alpha_range")
        *_, n = alpha_count(alpha_range, alpha_step)
        memory(f"alpha_step = {alpha_step:g} over alpha_range {tuple(alpha_range)} "
               f"({n:.3g} amplitudes)", kernel.grid_bytes(n, 1, 8, 101, 400, True, 1, 1))
        return alpha_grid(alpha_range, alpha_step)
    try:
        a = np.atleast_1d(np.asarray(alphas, dtype=float))
    except (TypeError, ValueError):
        raise ValueError(f"alphas must be a sequence of numbers (got {alphas!r})") from None
    if a.ndim != 1 or a.size == 0:
        raise ValueError("alphas must be a non-empty 1-D sequence")
    if not np.all(np.isfinite(a)) or np.any(a < 0) or np.any(a > ALPHA_MAX):
        raise ValueError(f"alphas must be finite and in [0, {ALPHA_MAX:g}]")
    return a


def _z0(z0, name="z0"):
    try:
        z = np.asarray(z0, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be 4 numbers (theta, theta', r, s) (got {z0!r})") \
            from None
    return z


def plan_sweep(hb, omega, alphas=None, *, law=None, e=None, xi=None, alpha_range=None,
               alpha_step=0.001, z0=Z0_STUDY, periods=500, n_steps=None, window=None,
               lyapunov=True, early_stop=True, threads=None, tol=TOL, pmax=PMAX,
               lam_tol=LAM_TOL, max_impacts=None, settle_tol=SETTLE_TOL,
               settle_reps=SETTLE_REPS, n_points=None, n_impact_points=400,
               attractors=True, stop_at_overturn=True, uncertainty=None,
               chunk=None) -> GridPlan:
    """Validate the inputs of :func:`sweep` (same parameters) into a :class:`GridPlan`."""
    alphas = _alphas(alphas, alpha_range, alpha_step)
    block = make_block(hb, float(alphas[0]), omega, law, e, xi)
    make_block(hb, float(alphas.max()), omega, law, e, xi)
    z = _z0(z0).ravel()
    if z.shape != (4,):
        raise ValueError(f"z0 must be 4 numbers (theta, theta', r, s) (got {z.size})")
    _check_state(z, block)
    phi, r0, s0 = forcing_phase(None, z[2], z[3], "closed", embedded_hint=False)
    n = alphas.size
    par, ipar, cpar, settings, threads, chunk = _grid_common(
        block, phi, periods=periods, n_steps=n_steps, window=window, early_stop=early_stop,
        tol=tol, pmax=pmax, lam_tol=lam_tol, max_impacts=max_impacts, settle_tol=settle_tol,
        settle_reps=settle_reps, threads=threads, chunk=chunk,
        stop_at_overturn=stop_at_overturn)
    n_points = _n_points("n_points", n_points, settings["periods"] - settings["window"] + 1)
    n_impact_points = integer("n_impact_points", n_impact_points, 0, 10**6)
    nbytes = grid_memory("alphas" if alpha_range is None else "alpha_range and alpha_step", n,
                         settings, threads, chunk, n_points, n_impact_points, lyapunov)
    y0s = np.tile(np.array([z[0], z[1], r0, s0]), (n, 1))
    pars = np.tile(par, (n, 1))
    pars[:, ig.P_AW2] = alphas * block.omega**2
    settings.update(z0=tuple(z), lyapunov=bool(lyapunov), law=block.law,
                    restitution=block.restitution)
    return GridPlan(kind="sweep", block=block, y0s=y0s, pars=pars, ipar=ipar, cpar=cpar,
                    tangent=bool(lyapunov), n_pts=n_points, n_imp_pts=n_impact_points,
                    threads=threads, chunk=chunk, axes=dict(alpha=alphas), shape=(n,),
                    settings=settings, memory_bytes=nbytes, attractors=bool(attractors),
                    phi=phi,
                    uncertainty=_uncertainty(uncertainty))


def plan_basin(hb, alpha, omega, *, law=None, e=None, xi=None, grid=100,
               theta_range=(-1.0, 1.0), dtheta_range=(-1.0, 1.0), r0=None, s0=None,
               phase=None, periods=500, n_steps=None, window=None, lyapunov=False,
               early_stop=True, threads=None, tol=TOL, pmax=PMAX, lam_tol=LAM_TOL,
               max_impacts=None, settle_tol=SETTLE_TOL, settle_reps=SETTLE_REPS,
               attractors=True, stop_at_overturn=True, uncertainty=None,
               chunk=None) -> GridPlan:
    """Validate the inputs of :func:`basin` (same parameters) into a :class:`GridPlan`."""
    block = make_block(hb, alpha, omega, law, e, xi)
    grid = integer("grid", grid, 1, int(math.isqrt(MAX_CELLS)))  # the memory check refuses first
    th_rng = pair("theta_range", theta_range)
    if max(abs(th_rng[0]), abs(th_rng[1])) >= block.theta_over:
        raise ValueError(f"theta_range must lie inside (-theta_over, theta_over) = "
                         f"(-{block.theta_over:.6g}, {block.theta_over:.6g}) (got {th_rng})")
    dth_rng = pair("dtheta_range", dtheta_range, -1e6, 1e6)
    phi, r0, s0 = forcing_phase(phase, r0, s0, "closed", embedded_hint=False)
    par, ipar, cpar, settings, threads, chunk = _grid_common(
        block, phi, periods=periods, n_steps=n_steps, window=window, early_stop=early_stop,
        tol=tol, pmax=pmax, lam_tol=lam_tol, max_impacts=max_impacts, settle_tol=settle_tol,
        settle_reps=settle_reps, threads=threads, chunk=chunk,
        stop_at_overturn=stop_at_overturn)
    n_pts = settings["pmax"] if attractors else 0
    nbytes = grid_memory(f"grid = {grid}", float(grid) ** 2, settings, threads, chunk,
                         n_pts, lyapunov=lyapunov)
    th = np.linspace(*th_rng, grid)
    dth = np.linspace(*dth_rng, grid)
    TH, DTH = np.meshgrid(th, dth, indexing="ij")
    y0s = np.stack([TH.ravel(), DTH.ravel(), np.full(TH.size, r0), np.full(TH.size, s0)], 1)
    pars = np.tile(par, (TH.size, 1))
    settings.update(r0=r0, s0=s0, phase=phi, lyapunov=bool(lyapunov), law=block.law,
                    restitution=block.restitution)
    return GridPlan(kind="basin", block=block, y0s=y0s, pars=pars, ipar=ipar, cpar=cpar,
                    tangent=bool(lyapunov), n_pts=n_pts, n_imp_pts=0, threads=threads,
                    chunk=chunk, axes=dict(theta0=th, dtheta0=dth), shape=(grid, grid),
                    settings=settings, memory_bytes=nbytes, attractors=bool(attractors),
                    phi=phi,
                    uncertainty=_uncertainty(uncertainty))


def plan_plane(hb, alpha_range, omega_range, *, grid=(50, 50), law=None, e=None, xi=None,
               z0=Z0_STUDY, periods=500, n_steps=None, window=None, lyapunov=True,
               early_stop=True, threads=None, tol=TOL, pmax=PMAX, lam_tol=LAM_TOL,
               max_impacts=None, settle_tol=SETTLE_TOL, settle_reps=SETTLE_REPS,
               attractors=True, stop_at_overturn=True, uncertainty=None,
               chunk=None) -> GridPlan:
    """Validate the inputs of :func:`plane` (same parameters) into a :class:`GridPlan`."""
    a0, a1 = pair("alpha_range", alpha_range, 0.0, ALPHA_MAX)
    w0, w1 = pair("omega_range", omega_range, *OMEGA_RANGE)
    try:
        na, nw = grid
    except (TypeError, ValueError):
        raise ValueError(f"grid must be two integers (got {grid!r})") from None
    na = integer("grid[0]", na, 1, MAX_CELLS)
    nw = integer("grid[1]", nw, 1, MAX_CELLS)
    block = make_block(hb, a0, w0, law, e, xi)
    make_block(hb, a1, w1, law, e, xi)
    z = np.atleast_2d(_z0(z0))
    if z.ndim != 2 or z.shape[1] != 4 or z.shape[0] == 0:
        raise ValueError("z0 must be 4 numbers (theta, theta', r, s) or m rows of them")
    for row in z:
        _check_state(row, block)
    phis = [forcing_phase(None, r, s, "closed", embedded_hint=False)[0] for r, s in z[:, 2:]]
    M = z.shape[0]
    par, ipar, cpar, settings, threads, chunk = _grid_common(
        block, phis[0], periods=periods, n_steps=n_steps, window=window,
        early_stop=early_stop, tol=tol, pmax=pmax, lam_tol=lam_tol, max_impacts=max_impacts,
        settle_tol=settle_tol, settle_reps=settle_reps, threads=threads, chunk=chunk,
        stop_at_overturn=stop_at_overturn)
    n_pts = settings["pmax"] if attractors else 0
    nbytes = grid_memory(f"grid = ({na}, {nw})", float(M) * na * nw, settings, threads,
                         chunk, n_pts, lyapunov=lyapunov)
    alphas = np.linspace(a0, a1, na)
    omegas = np.linspace(w0, w1, nw)
    Z, A, W = np.meshgrid(np.arange(M), alphas, omegas, indexing="ij")
    n = Z.size
    pars = np.tile(par, (n, 1))
    pars[:, ig.P_OMEGA] = W.ravel()
    pars[:, ig.P_AW2] = A.ravel() * W.ravel() ** 2
    pars[:, ig.P_H] = 2.0 * math.pi / W.ravel() / settings["n_steps"]
    pars[:, ig.P_PHI] = np.asarray(phis)[Z.ravel()]
    zz = z[Z.ravel()]
    y0s = np.stack([zz[:, 0], zz[:, 1], np.sin(pars[:, ig.P_PHI]), np.cos(pars[:, ig.P_PHI])],
                   1)
    settings.update(lyapunov=bool(lyapunov), law=block.law, restitution=block.restitution)
    return GridPlan(kind="plane", block=block, y0s=y0s, pars=pars, ipar=ipar, cpar=cpar,
                    tangent=bool(lyapunov), n_pts=n_pts, n_imp_pts=0, threads=threads,
                    chunk=chunk, axes=dict(alpha=alphas, omega=omegas, z0=z),
                    shape=(M, na, nw), settings=settings, memory_bytes=nbytes,
                    attractors=bool(attractors),
                    uncertainty=_uncertainty(uncertainty))


def run(plan: GridPlan, *, progress=False, client=None, store=None, message=None):
    """Execute a :class:`GridPlan`; returns its :class:`SweepResult`, :class:`BasinResult` or
    :class:`PlaneResult`.

    Parameters
    ----------
    progress : bool
        Show progress on stderr.
    client : dask.distributed.Client, optional
        Run the chunks of cells on this cluster (:mod:`rockjit.storage.chunkstore`).
    store : path, optional
        Directory for finished chunks: a rerun with the same inputs computes only what is
        missing.
    message : callable, optional
        ``message(text)`` hears the chunk store's notes (a lock taken over, a damaged chunk
        recomputed); default a line on stderr.
    """
    p = plan
    out = runner.run_grid(p.y0s, p.pars, p.ipar, p.cpar, tangent=p.tangent, n_pts=p.n_pts,
                          n_imp_pts=p.n_imp_pts, threads=p.threads, progress=progress,
                          label=p.kind, chunk=p.chunk, client=client, store=store,
                          message=message, lanes=p.lanes)
    res = out["res"]
    label = res[:, kernel.R_LABEL].astype(np.int64).reshape(p.shape)
    period = res[:, kernel.R_PERIOD].astype(np.int64).reshape(p.shape)
    lam = res[:, kernel.R_LAM1].reshape(p.shape)
    t_end = res[:, kernel.R_T].reshape(p.shape)
    common = dict(block=p.block, settings=dict(p.settings), label=label, period=period,
                  t_end=t_end)
    if p.attractors:
        common["attractor"], common["attractors"] = _identify(p, res, out["pts"],
                                                              out["n_got"])
    if p.kind == "sweep":
        result = SweepResult(alpha=p.axes["alpha"], lambda_max=lam, strobe=out["pts"],
                           impact_section=out["imp"], t_overturn=res[:, kernel.R_TOVER],
                           motion=res[:, kernel.R_MOTION].astype(np.int64), **common)
    elif p.kind == "basin":
        result = BasinResult(theta0=p.axes["theta0"], dtheta0=p.axes["dtheta0"],
                             lambda_max=lam if p.tangent else None, **common)
    else:
        result = PlaneResult(alpha=p.axes["alpha"], omega=p.axes["omega"], z0=p.axes["z0"],
                             lambda_max=lam, **common)
    if p.uncertainty is not None:
        result.uncertain = uncertain_cells(p, result, p.uncertainty, progress=progress,
                                           client=client)
        result.settings["uncertainty"] = p.uncertainty
    return result


def uncertain_cells(plan, result, eps, *, seed=0, progress=False, client=None):
    """Which cells of a grid change outcome when their initial state moves by ``eps``
    (Grebogi, McDonald, Ott & Yorke 1983; rockjit.basins.fate).

    Each cell's ``(theta0, theta0')`` is moved by ``eps`` times its size (absolute where 0) in
    a seeded random direction and run again with the same plan; a cell is uncertain when the
    moved run reaches another outcome: another behaviour or period, or another attractor (the
    two maps' attractors matched by their cycles, rockjit.basins.identity). Returns a boolean array
    shaped like the labels.
    """
    from dataclasses import replace
    rng = np.random.default_rng(seed)
    ang = rng.uniform(0.0, 2.0 * np.pi, plan.y0s.shape[0])
    y0s = plan.y0s.copy()
    scale = np.where(np.abs(y0s[:, :2]) > 0, np.abs(y0s[:, :2]), 1.0)
    y0s[:, 0] += eps * scale[:, 0] * np.cos(ang)
    y0s[:, 1] += eps * scale[:, 1] * np.sin(ang)
    moved = run(replace(plan, y0s=y0s, uncertainty=None), progress=progress, client=client)
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


def _identify(p, res, pts, n_got):
    """Attractor ids (shaped like the labels) and attractors of a plan's cells, with the
    Floquet multipliers of the periodic ones (rockjit.basins.identity)."""
    label = res[:, kernel.R_LABEL].astype(np.int64)
    period = res[:, kernel.R_PERIOD].astype(np.int64)
    lam = res[:, [kernel.R_LAM1, kernel.R_LAM2]] if p.tangent else None
    n_steps = p.settings["n_steps"]
    if p.kind == "basin":
        ids, found = identify(label, period, pts, n_got, lam)
        blocks = {a.id: p.block for a in found}
        phis = {a.id: p.phi for a in found}
    else:
        shape = p.shape if p.kind == "sweep" else p.shape[1:]
        per_state = int(np.prod(shape))
        ids = np.empty(label.size, dtype=np.int64)
        found, blocks, phis = [], {}, {}
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
                row = p.pars[cell]
                blocks[a.id] = p.block.replace(alpha=row[ig.P_AW2] / row[ig.P_OMEGA] ** 2,
                                               omega=row[ig.P_OMEGA])
                phis[a.id] = row[ig.P_PHI]
            found += found_m
    for a in found:
        if a.period:
            a.multipliers, a.lam = floquet(blocks[a.id], phis[a.id], n_steps, a.points[0],
                                           a.period)
    return ids.reshape(p.shape), found


def sweep(hb, omega, alphas=None, *, law=None, e=None, xi=None, alpha_range=None,
          alpha_step=0.001, z0=Z0_STUDY, periods=500, n_steps=None, window=None,
          lyapunov=True, early_stop=True, threads=None, progress=False, tol=TOL, pmax=PMAX,
          lam_tol=LAM_TOL, max_impacts=None, settle_tol=SETTLE_TOL,
          settle_reps=SETTLE_REPS, n_points=None, n_impact_points=400, attractors=True,
          stop_at_overturn=True, uncertainty=None, client=None, store=None,
          chunk=None) -> SweepResult:
    """Bifurcation sweep over the forcing amplitude ``alpha`` (SPEC.md §7).

    Parameters
    ----------
    hb, omega : float
        Slenderness and forcing frequency.
    alphas : array_like, optional
        The amplitudes; or give ``alpha_range=(start, end)`` and ``alpha_step`` (not both).
    law, e, xi :
        As in :func:`rockjit.simulate`.
    z0 : sequence of 4 floats
        ``(theta0, theta0', r0, s0)``, default the study's.
    periods, n_steps, window, max_impacts :
        As in :func:`rockjit.simulate` (``n_steps`` defaults to :data:`GRID_N`); the window is
        the classified stretch of a full run.
    lyapunov : bool
        Compute ``lambda_max`` (needed to tell chaotic from aperiodic).
    early_stop : bool
        Stop each run once it has settled on a periodic orbit (see the module docstring).
    threads : int, optional
        numba threads (default all); results do not depend on it.
    progress : bool
        Show progress on stderr.
    tol, pmax, lam_tol, settle_tol, settle_reps :
        Classification settings (:mod:`rockjit._engine.classify`).
    n_points : int, optional
        Stroboscopic samples kept per alpha (default the window length).
    n_impact_points : int
        Impact-section points kept per alpha.
    uncertainty : float, optional
        Flag the cells whose outcome changes when their initial state moves by this relative
        amount (``result.uncertain``, :func:`uncertain_cells`); costs a second run of the grid.
    stop_at_overturn : bool
        ``False`` integrates on past the overturning threshold, as the study's code did: such
        a cell keeps the label overturn (``t_overturn`` its first crossing) and its samples and
        exponents describe the motion after the fall (``motion``, its behaviour).
    attractors : bool
        Identify the attractors (:mod:`rockjit.basins.identity`): ``result.attractor`` (ids) and
        ``result.attractors``; along a sweep or plane by continuation between neighbours.
    client : dask.distributed.Client, optional
        Run the chunks of cells on this cluster (:mod:`rockjit.storage.chunkstore`).
    store : path, optional
        Directory for finished chunks: a rerun with the same inputs computes only what is
        missing.
    chunk : int, optional
        Cells per chunk (the unit of progress, of Dask tasks and of resumption); default
        about a twentieth of the grid, at least 64.
    """
    p = plan_sweep(hb, omega, alphas, law=law, e=e, xi=xi, alpha_range=alpha_range,
                   alpha_step=alpha_step, z0=z0, periods=periods, n_steps=n_steps,
                   window=window, lyapunov=lyapunov, early_stop=early_stop, threads=threads,
                   tol=tol, pmax=pmax, lam_tol=lam_tol, max_impacts=max_impacts,
                   settle_tol=settle_tol, settle_reps=settle_reps, n_points=n_points,
                   n_impact_points=n_impact_points, attractors=attractors,
                   stop_at_overturn=stop_at_overturn, uncertainty=uncertainty, chunk=chunk)
    return run(p, progress=progress, client=client, store=store)


def basin(hb, alpha, omega, *, law=None, e=None, xi=None, grid=100, theta_range=(-1.0, 1.0),
          dtheta_range=(-1.0, 1.0), r0=None, s0=None, phase=None, periods=500,
          n_steps=None, window=None, lyapunov=False, early_stop=True, threads=None,
          progress=False, tol=TOL, pmax=PMAX, lam_tol=LAM_TOL, max_impacts=None,
          settle_tol=SETTLE_TOL, settle_reps=SETTLE_REPS, attractors=True,
          stop_at_overturn=True, uncertainty=None, client=None, store=None,
          chunk=None) -> BasinResult:
    """Basin of attraction over ``(theta0, theta0')`` on a ``grid x grid`` lattice.

    The forcing phase is fixed (default ``(r0, s0) = (0, 1)``, SPEC.md §7). ``label[i, j]``
    belongs to ``theta0[i]``, ``dtheta0[j]``. Other parameters (``client`` and ``store``
    included) as in :func:`sweep`.
    """
    p = plan_basin(hb, alpha, omega, law=law, e=e, xi=xi, grid=grid, theta_range=theta_range,
                   dtheta_range=dtheta_range, r0=r0, s0=s0, phase=phase, periods=periods,
                   n_steps=n_steps, window=window, lyapunov=lyapunov, early_stop=early_stop,
                   threads=threads, tol=tol, pmax=pmax, lam_tol=lam_tol,
                   max_impacts=max_impacts, settle_tol=settle_tol, settle_reps=settle_reps,
                   attractors=attractors, stop_at_overturn=stop_at_overturn,
                   uncertainty=uncertainty, chunk=chunk)
    return run(p, progress=progress, client=client, store=store)


def plane(hb, alpha_range, omega_range, *, grid=(50, 50), law=None, e=None, xi=None,
          z0=Z0_STUDY, periods=500, n_steps=None, window=None, lyapunov=True,
          early_stop=True, threads=None, progress=False, tol=TOL, pmax=PMAX, lam_tol=LAM_TOL,
          max_impacts=None, settle_tol=SETTLE_TOL, settle_reps=SETTLE_REPS,
          attractors=True, stop_at_overturn=True, uncertainty=None, client=None, store=None,
          chunk=None) -> PlaneResult:
    """Behaviour and ``lambda_max`` at each ``(alpha, omega)`` of a grid (a rocking chart).

    Parameters
    ----------
    hb : float
        Slenderness.
    alpha_range, omega_range : pair of float
        Ranges, ends included: ``0 <= alpha0 <= alpha1`` and ``0 < omega0 <= omega1``.
    grid : pair of int
        Points ``(NA, NW)`` along alpha and omega.
    z0 : array_like, shape (4,) or (m, 4)
        Initial state(s) ``(theta, theta', r, s)``; ``(r, s)`` fixes the forcing phase.
    Other parameters as in :func:`sweep` (``client`` and ``store`` included).
    """
    p = plan_plane(hb, alpha_range, omega_range, grid=grid, law=law, e=e, xi=xi, z0=z0,
                   periods=periods, n_steps=n_steps, window=window, lyapunov=lyapunov,
                   early_stop=early_stop, threads=threads, tol=tol, pmax=pmax,
                   lam_tol=lam_tol, max_impacts=max_impacts, settle_tol=settle_tol,
                   settle_reps=settle_reps, attractors=attractors,
                   stop_at_overturn=stop_at_overturn, uncertainty=uncertainty, chunk=chunk)
    return run(p, progress=progress, client=client, store=store)


def classify_result(result, *, tol=TOL, pmax=PMAX, lam_tol=LAM_TOL):
    """Behaviour name and period of a :class:`rockjit.Result` (window of the run).

    Uses the same compiled classifier as the sweeps and basins on the result's stroboscopic
    samples from ``window`` on. Returns ``(name, period)``.
    """
    if result.status == "overturned" or math.isfinite(result.t_overturn):
        return "overturn", 0
    if result.status == "rest":
        return "rest", 0
    if result.status not in ("done", "settled"):
        return "unresolved", 0
    k1 = result.strobe.shape[0] - 1
    k0 = int(round(result.window[0] / result.period)) if result.window else \
        int(round(0.8 * result.periods))
    k0 = min(k0, k1)
    per_imp = np.zeros(k1 + 1, dtype=np.int64)
    t_imp = result.impacts[:, 0]
    for k in range(k1 + 1):
        per_imp[k] = np.count_nonzero(t_imp <= k * result.period * (1 + 1e-12))
    half = np.zeros((k1 + 1, 4))
    half[:result.strobe_half.shape[0]] = result.strobe_half[:k1 + 1]
    lam = result.lambda_max
    code, p = classify(result.strobe, half, per_imp, k0, k1, lam, not math.isnan(lam),
                       float(tol), int(pmax), float(lam_tol))
    return BEHAVIOURS[code], int(p)
