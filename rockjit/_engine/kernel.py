"""The one owner of the compiled kernels' inputs and outputs: packing, allocating, unpacking.

The kernels (:mod:`rockjit._engine.integrate` for one run, :func:`_grid` here for grids of runs) read a
float parameter vector ``par`` and integer settings ``ipar`` and fill an
:data:`rockjit._engine.integrate.Outputs`; their layouts are declared in :mod:`rockjit._engine.integrate`. This
module is the only one that packs those vectors (:func:`pack`, :func:`settings`), allocates the
outputs (:func:`outputs`), estimates their memory before anything is allocated
(:func:`run_bytes`, :func:`grid_bytes`), and reads them back into the result types of
:mod:`rockjit.result` (:func:`run_single`, :func:`run_grid`).

Grids (three tiers): :func:`_cell`, a serial compiled worker, runs one cell and
classifies it (:mod:`rockjit._engine.classify`); :func:`_grid`, ``parallel=True``, runs a chunk of cells
with ``prange``, each iteration with private scratch writing only its own row of the outputs,
so results do not depend on the number of threads; :func:`run_chunk` is the unit of work of
:mod:`rockjit.storage.chunkstore` (in this process or on a Dask worker) and :func:`run_grid` runs all chunks.
"""

from __future__ import annotations

import functools
import math
from contextlib import contextmanager

import numba
import numpy as np
from numba import prange

from . import integrate as ig
from .cell import (C_LAMTOL, C_TOL, N_RES, R_K0, R_K1, R_LABEL, R_LAM1, R_LAM2,  # noqa: F401
                   R_MOTION, R_NIMP, R_PERIOD, R_STATUS, R_T, R_TOVER, _classify, _collect)
from .._jit import jit
from ..model import damping_rate, initial_side
from ..result import Result
from ..validate import integer

__all__ = ["IMPACT_RECORD", "LANES_MAX", "N_RES", "grid_bytes", "outputs", "pack", "run_bytes",
           "run_chunk", "run_chunk_counted", "run_single", "settings"]

#: Rows of the impact record of a single run: beyond this many impacts only the latest are kept
#: (``Result.n_impacts`` counts all of them).
IMPACT_RECORD = 1_000_000

# ---------------------------------------------------------------------------------------------
# packing
# ---------------------------------------------------------------------------------------------

def pack(block, forcing, phi, integration, n_steps, settle_tol=0.0):
    """The float parameter vector ``par`` of a block under a harmonic forcing at phase ``phi``
    with ``n_steps`` steps per period (layout ``P_*`` in :mod:`.integrate`)."""
    par = np.zeros(ig.N_PAR)
    par[ig.P_THC] = block.thc
    par[ig.P_XI] = block.xi
    par[ig.P_E] = block.restitution
    par[ig.P_LAW], par[ig.P_LAW_SHAPE] = block.impact_law
    par[ig.P_AW2] = forcing.alpha * forcing.omega**2
    par[ig.P_OMEGA] = forcing.omega
    par[ig.P_PHI] = phi
    par[ig.P_COT] = block.cot
    par[ig.P_THOVER] = integration.theta_over
    par[ig.P_REST] = integration.rest_speed
    par[ig.P_H] = forcing.period / n_steps
    par[ig.P_SETTLE_TOL] = settle_tol
    return par


def vary(pars, *, alpha=None, omega=None, phi=None, n_steps=None):
    """Rows of ``pars`` (shape ``(n, N_PAR)``, changed in place and returned) with the forcing
    varied per row: amplitudes ``alpha`` at the rows' frequencies, or frequencies ``omega``
    (with ``alpha``, the step ``T/n_steps`` follows), or phases ``phi``."""
    if omega is not None:
        pars[:, ig.P_OMEGA] = omega
        pars[:, ig.P_AW2] = alpha * omega ** 2
        pars[:, ig.P_H] = 2.0 * math.pi / omega / n_steps
    elif alpha is not None:
        pars[:, ig.P_AW2] = alpha * pars[0, ig.P_OMEGA] ** 2
    if phi is not None:
        pars[:, ig.P_PHI] = phi
    return pars


def forcing_of(par):
    """``(alpha, omega, phi)`` of a parameter row."""
    return par[ig.P_AW2] / par[ig.P_OMEGA] ** 2, par[ig.P_OMEGA], par[ig.P_PHI]


def grid_results(out):
    """A grid's scalar results by name from the kernels' rows (layout ``R_*``): ``label``,
    ``period``, ``motion`` (int64); ``lam1``, ``lam2``, ``t_end``, ``t_overturn``."""
    res = out["res"]
    return dict(label=res[:, R_LABEL].astype(np.int64),
                period=res[:, R_PERIOD].astype(np.int64),
                motion=res[:, R_MOTION].astype(np.int64),
                lam1=res[:, R_LAM1], lam2=res[:, R_LAM2], t_end=res[:, R_T],
                t_overturn=res[:, R_TOVER])


def classification_vector(classification):
    """The classification's float settings ``cpar`` (layout ``C_*``)."""
    cpar = np.zeros(2)
    cpar[C_TOL] = classification.tol
    cpar[C_LAMTOL] = classification.lam_tol
    return cpar


#: Between two renormalisations the second tangent vector may lose at most exp(-QR_CONTRACTION)
#: against the first: damping separates the two exponents by about 3/4 xi, and once the second
#: vector's own direction falls below rounding relative to the first, Gram-Schmidt finds
#: nothing left of it and the kernel would take it for a collapse (lambda2 = -inf with no rest
#: and no impact). exp(-20) = 2e-9 keeps seven digits of it.
QR_CONTRACTION = 20.0


def default_qr_every(n_steps, h, xi):
    """Grid steps between renormalisations: twice a period, or often enough that damping
    (rate ``3/4 xi``, step ``h``) separates the two vectors by at most
    ``exp(-QR_CONTRACTION)``."""
    n = n_steps // 2
    c = damping_rate(xi) * h
    if c > 0.0:
        # compared in floating point first: for a damping as small as 1e-320 the quotient is
        # infinite (or beyond any integer a step counter holds), and then twice a period stays
        q = QR_CONTRACTION / c
        if q < n:
            n = max(1, int(q))
    return n


def settings(n_steps, periods, max_impacts, window, *, stride=1, settle_reps=0, qr_every=None,
             pmax=1, stop_at_overturn=True, h=0.0, xi=0.0):
    """The integer settings ``ipar`` (layout ``I_*`` in :mod:`rockjit._engine.integrate`);
    ``qr_every`` defaults to :func:`default_qr_every` (``h`` the largest step, ``xi`` the
    damping)."""
    ipar = np.zeros(ig.N_IPAR, dtype=np.int64)
    ipar[ig.I_N] = n_steps
    ipar[ig.I_PERIODS] = periods
    ipar[ig.I_MAXIMP] = max_impacts
    ipar[ig.I_STRIDE] = stride
    ipar[ig.I_WINDOW] = window
    ipar[ig.I_SETTLE] = settle_reps
    ipar[ig.I_QR] = default_qr_every(n_steps, h, xi) if qr_every is None else qr_every
    ipar[ig.I_PMAX] = pmax
    ipar[ig.I_CONTINUE] = 0 if stop_at_overturn else 1
    return ipar


def _impact_rows(max_impacts):
    return min(max_impacts, IMPACT_RECORD)


def outputs(periods, max_impacts, n_traj, tangent):
    """Fresh :data:`rockjit._engine.integrate.Outputs` for one run."""
    return ig.Outputs(
        strobe=np.zeros((periods + 1, 4)), half=np.zeros((periods, 4)),
        impacts=np.empty((_impact_rows(max_impacts), 3)),  # rows filled are all that is read
        traj=np.zeros((n_traj, 5)), lam_run=np.zeros((periods + 1 if tangent else 1, 3)),
        per_imp=np.zeros(periods + 1, dtype=np.int64), iout=np.zeros(ig.N_IOUT, dtype=np.int64),
        fout=np.zeros(ig.N_FOUT))


def run_bytes(periods, n_steps, max_impacts, n_traj, tangent):
    """Bytes one run allocates (a float: large requests must not overflow)."""
    p = float(periods)
    return 8.0 * (4 * (p + 1) + 4 * p + 3 * _impact_rows(max_impacts) + 5 * float(n_traj)
                  + 3 * (p + 1 if tangent else 1) + (p + 1)
                  + float(n_steps) * (ig.N_STAGES + 1))


def grid_bytes(n_cells, periods, n_steps, n_pts, n_imp_pts, tangent, chunk, threads):
    """Bytes a grid allocates: its outputs and inputs, plus each thread's scratch."""
    per_cell = 8.0 * (N_RES + 2 * max(n_pts, 1) + 2 * max(n_imp_pts, 1) + 2 + 4 + ig.N_PAR)
    scratch = run_bytes(periods, n_steps, max(n_imp_pts, 1), 1, tangent)
    return float(n_cells) * per_cell * 2 + float(min(chunk, n_cells)) * per_cell \
        + float(threads) * scratch


# ---------------------------------------------------------------------------------------------
# one run
# ---------------------------------------------------------------------------------------------

def run_single(p):
    """One compiled run of a :class:`rockjit.single.RunPlan` (validated); a Result."""
    run, par, ipar = prepare_single(p)
    out = single_outputs(p)
    y0 = np.asarray(p.y0, dtype=float)
    code = run(y0, initial_side(y0[0], y0[1]), par, ipar, out)
    return single_result(p, code, out)


def prepare_single(p):
    """What a compiled run of the plan ``p`` needs besides its initial state and its outputs
    (:func:`single_outputs`): ``(kernel, par, ipar)``."""
    block, forcing, n_steps, periods = p.block, p.forcing, p.n_steps, p.periods
    record_stride = p.record_stride
    run = ig.build(embed4=forcing.embedded, tangent=p.lyapunov)
    par = pack(block, forcing, p.phi, p.integration, n_steps)
    ipar = settings(n_steps, periods, p.max_impacts, p.window, stride=record_stride or 1,
                    qr_every=p.integration.qr_every,
                    stop_at_overturn=p.integration.stop_at_overturn,
                    h=forcing.period / n_steps, xi=block.xi)
    return run, par, ipar


def single_outputs(p):
    """Fresh outputs for a run of plan ``p``."""
    stride = p.record_stride
    n_traj = p.periods * p.n_steps // stride + 1 if stride else 1
    return outputs(p.periods, p.max_impacts, n_traj, p.lyapunov)


def single_result(p, code, out, forcing=None):
    """The :class:`rockjit.Result` of plan ``p`` (run under ``forcing`` when given: the plan's
    at another amplitude) from the kernel's status ``code`` and outputs ``out`` (views of
    ``out``'s arrays: give each run its own outputs)."""
    forcing = p.forcing if forcing is None else forcing
    # the scalar outputs as Python numbers, read once (indexing the arrays one number at a
    # time was a third of a short run's overhead)
    iout, fout = out.iout.tolist(), out.fout.tolist()
    n_imp, ns = iout[ig.O_IMPACTS], iout[ig.O_NSTROBE]
    res = Result(
        block=p.block, forcing=forcing, integration=p.integration, method="rockjit",
        status=ig.STATUS_NAMES[int(code)], t=fout[ig.F_T],
        state=out.fout[ig.F_TH:ig.F_S + 1].copy(), period=forcing.period, n_steps=p.n_steps,
        periods=p.periods, strobe=out.strobe[:ns], strobe_half=out.half[:iout[ig.O_NHALF]],
        impacts=_impacts_in_order(out.impacts, n_imp), n_impacts=n_imp,
        n_grid_steps=iout[ig.O_STEPS], n_rhs=iout[ig.O_RHS],
        max_error_estimate=fout[ig.F_MAXERR],
        trajectory=out.traj[:iout[ig.O_NTRAJ]] if p.record_stride else None,
        n_rest=iout[ig.O_NREST], n_rest_window=iout[ig.O_NREST_WIN],
        n_impacts_window=iout[ig.O_NIMP_WIN], n_locate_unconverged=iout[ig.O_UNCONVERGED],
        t_overturn=fout[ig.F_TOVER],
    )
    # events located by genuine steps because the step's interpolant was not trusted
    res.extra["locate_resteps"] = iout[ig.O_RESTEP]
    if p.lyapunov:
        # the tangent matrix at the end: the flow's Jacobian since the last renormalisation;
        # with qr_every = 0 that is the whole run's, and zero once a perturbation died (a rest
        # phase, an impact with e = 0)
        tangent = out.fout[ig.F_V:ig.F_V + 4].reshape(2, 2, order="F").copy()
        res.extra["collapses"] = iout[ig.O_NCOL]
        if p.integration.qr_every == 0 and iout[ig.O_NCOL] > 0:
            tangent[:] = 0.0
        res.extra["tangent"] = tangent
        res.window = (p.window * forcing.period, res.t)
        lam_run = out.lam_run[:ns]
        running = np.where(lam_run[:, 2:3] > 0, -math.inf, lam_run[:, :2])
        if res.status == "rest":
            # at rest for good every perturbation dies out in finite time
            res.lyapunov = np.array([-math.inf, -math.inf])
        else:
            # Gram-Schmidt's first column carries the largest growth only asymptotically; over
            # a finite window a (near-)degenerate pair may come out in either order
            res.lyapunov = np.sort(out.fout[ig.F_LAM1:ig.F_LAM2 + 1])[::-1].copy()
        res.lyapunov_running = -np.sort(-running, axis=1)
    return res


def _impacts_in_order(ring, n_imp):
    """The impact record in time order: the ring's rows from the oldest kept on."""
    cap = ring.shape[0]
    if n_imp <= cap:
        return ring[:n_imp]
    q = n_imp % cap
    return np.concatenate([ring[q:], ring[:q]])


# ---------------------------------------------------------------------------------------------
# grids
# ---------------------------------------------------------------------------------------------

@jit
def _cell(TANGENT, y0, side0, par, ipar, cpar, out, res):
    """Run one cell and classify it; scalar results go to ``res`` (layout ``R_*``)."""
    status = ig._run(None, TANGENT, y0, side0, par, ipar, out)
    _classify(TANGENT, status, ipar, cpar, out, res)


@jit(parallel=True)
def _grid(TANGENT, y0s, pars, ipar, cpar, n_pts, n_imp_pts, res, pts, imp_pts, n_got,
          n_imp_got):
    """Cell i starts from ``y0s[i]`` with the parameter row ``pars[i]`` (integrate's layout).

    Writes ``res[i]`` (scalars), and when ``n_pts > 0`` the last stroboscopic samples
    ``pts[i, :, :]`` (``theta, theta'`` at kT over the classified stretch) and when
    ``n_imp_pts > 0`` the impact section ``imp_pts[i, :, :]`` (``t mod T, theta'-``).
    """
    n = y0s.shape[0]
    periods = ipar[ig.I_PERIODS]
    cap = max(n_imp_pts, 1)
    for i in prange(n):
        par = pars[i]
        T = par[ig.P_H] * ipar[ig.I_N]
        out = ig.Outputs(np.zeros((periods + 1, 4)), np.zeros((periods + 1, 4)),
                         np.zeros((cap, 3)), np.zeros((1, 5)),
                         np.zeros((periods + 1 if TANGENT is not None else 1, 3)),
                         np.zeros(periods + 1, dtype=np.int64),
                         np.zeros(ig.N_IOUT, dtype=np.int64), np.zeros(ig.N_FOUT))
        y0 = y0s[i]
        _cell(TANGENT, y0, initial_side(y0[0], y0[1]), par, ipar, cpar, out, res[i])
        _collect(i, T, n_pts, n_imp_pts, out, res, pts, imp_pts, n_got, n_imp_got)


@functools.lru_cache(maxsize=None)
def _kernel(tangent):
    """The grid kernel with or without tangent vectors (a thin closure forwarding the switch,
    ``True`` or ``None`` as :mod:`rockjit._engine.integrate` wants them, so that the module-level
    kernels are specialised and cached)."""
    TANGENT = True if tangent else None

    @jit
    def grid(y0s, pars, ipar, cpar, n_pts, n_imp_pts, res, pts, imp_pts, n_got, n_imp_got):
        _grid(TANGENT, y0s, pars, ipar, cpar, n_pts, n_imp_pts, res, pts, imp_pts, n_got,
              n_imp_got)

    return grid


@contextmanager
def _threads(threads):
    """Run with ``threads`` numba threads (default: all), small dynamic chunks."""
    old = numba.get_num_threads()
    if threads is not None:
        threads = integer("threads", threads, 1, numba.config.NUMBA_NUM_THREADS)
        numba.set_num_threads(threads)
    old_chunk = numba.get_parallel_chunksize()
    numba.set_parallel_chunksize(1)  # cells differ wildly in cost: balance dynamically
    try:
        yield
    finally:
        numba.set_parallel_chunksize(old_chunk)
        numba.set_num_threads(old)


def grid_outputs(n, n_pts, n_imp_pts):
    return dict(res=np.zeros((n, N_RES)), pts=np.full((n, max(n_pts, 1), 2), np.nan),
                imp=np.full((n, max(n_imp_pts, 1), 2), np.nan),
                n_got=np.zeros(n, dtype=np.int64), n_imp_got=np.zeros(n, dtype=np.int64))


def run_chunk(tangent, y0s, pars, ipar, cpar, n_pts, n_imp_pts, threads=None, lanes=None):
    """Run the grid kernel on one chunk of cells; returns its outputs by name.

    The unit of work of :func:`rockjit.storage.chunkstore.run_chunks`, in this process or on a Dask worker.
    ``lanes > 1`` runs that many cells per thread in lockstep (:mod:`rockjit._engine.lanes`; without
    tangent vectors only, the same outputs bit for bit); default :data:`DEFAULT_LANES`.
    """
    return run_chunk_counted(tangent, y0s, pars, ipar, cpar, n_pts, n_imp_pts, threads,
                             lanes)[0]


def run_chunk_counted(tangent, y0s, pars, ipar, cpar, n_pts, n_imp_pts, threads=None,
                      lanes=None, profile=False):
    """:func:`run_chunk`, and the lanes' counts per block of cells (``None`` without lanes;
    columns as :data:`N_LANE_COUNTS` says; the cycle counts only with ``profile``, which
    costs time)."""
    lanes = DEFAULT_LANES if lanes is None else integer("lanes", lanes, 1, LANES_MAX)
    y0s = np.ascontiguousarray(y0s)
    pars = np.ascontiguousarray(pars)
    out = grid_outputs(y0s.shape[0], n_pts, n_imp_pts)
    counts = None
    with _threads(threads):
        if lanes > 1 and not tangent:
            from . import lanes as ln
            n = y0s.shape[0]
            block = lane_block(n, numba.get_num_threads())
            counts = np.zeros(((n + block - 1) // block, N_LANE_COUNTS), dtype=np.int64)
            ln.grid_lanes(lanes, block, y0s, pars, ipar, cpar, n_pts, n_imp_pts, out["res"],
                          out["pts"], out["imp"], out["n_got"], out["n_imp_got"], bool(profile),
                          counts)
        else:
            _kernel(tangent)(y0s, pars, ipar, cpar, n_pts, n_imp_pts, out["res"], out["pts"],
                             out["imp"], out["n_got"], out["n_imp_got"])
    return out, counts


#: The lanes' counters per block (:func:`rockjit._engine.lanes.run_lanes`): fast steps (and
#: steps held at rest), scalar steps, vector steps; cycles in vector steps, in scalar steps, in
#: all; within the scalar steps, cycles in rest phases, in the steps after events, in locating
#: events, in impacts, in detection, in first steps taken again, at grid points
#: (:func:`rockjit._engine.lanes.scalar_step`).
N_LANE_COUNTS = 13

#: Cells per thread in lockstep at most (:data:`rockjit._engine.lanes.W`, the vector's width).
LANES_MAX = 8
#: Cells per thread in lockstep by default, for grids without tangent vectors (basins, erosion,
#: fates; the grids with exponents run one cell at a time): the fastest count on the study's
#: basin (benchmarks/results/lanes.md). The same outputs bit for bit whatever the count. The
#: lanes' kernel replaces the single-lane one in the ``grid`` variant.
DEFAULT_LANES = 8


def lane_block(n, threads):
    """Cells per block of lanes (one task of the parallel loop): 256, or fewer so that every
    thread gets four blocks (on one thread, nothing to balance: up to 256 in one block).
    Results do not depend on it."""
    if threads <= 1:
        return max(1, min(256, n))
    return max(1, min(256, -(-n // (4 * threads))))


def default_chunk(n):
    """Cells per chunk when none is given: about a twentieth of the grid, at least 64."""
    return max(64, -(-n // 20))


# ---------------------------------------------------------------------------------------------
# compiling ahead of time (``rockjit compile``)
# ---------------------------------------------------------------------------------------------

#: Every compiled variant: ``name -> (what it serves, its switches)``. A single run's variant
#: is ``(embed4, tangent)`` (recording a trajectory is a run-time switch of the same code); a
#: grid's is its tangent switch: ``grid+tangent`` calls the single run's loop compiled for the
#: same switches (it costs little once ``run+tangent`` is in the cache), ``grid`` runs the
#: lanes (:data:`DEFAULT_LANES`), whose loop holds its own copy of the step.
VARIANTS = {
    "run": ("single runs, trajectory", ("run", False, False)),
    "run+tangent": ("trajectory --lyapunov, the paper's runs, Floquet multipliers, periodic "
                    "orbits", ("run", False, True)),
    "embedded": ("the 4-D embedding: trajectory --forcing embedded, the paper's fates",
                 ("run", True, False)),
    "embedded+tangent": ("exponents with the embedding, the paper's fates", ("run", True, True)),
    "grid": ("basins, erosion, fate (8 cells per thread in lockstep)", ("grid", False)),
    "grid+tangent": ("sweeps, planes (exponents)", ("grid", True)),
}
#: What ``rockjit compile`` (and a cold ``rockjit paper``) compiles: every variant, since
#: ``rockjit paper`` (README's first command) uses each one; the longest first (the lanes'
#: grid kernel compiles the step again inside its own loop), so that the others share the
#: second core meanwhile (benchmarks/results/compile.md).
COMMON = ("grid", "run", "run+tangent", "embedded", "embedded+tangent", "grid+tangent")
assert sorted(COMMON) == sorted(VARIANTS)


def compile_variant(name):
    """Compile (or load from numba's cache) one variant of :data:`VARIANTS` by running it on
    a tiny input; returns the seconds it took. Module-level, so worker processes can run it."""
    import time as _time

    from types import SimpleNamespace

    from ..excitation import Harmonic
    from ..model import Block
    from ..settings import Integration
    t0 = _time.perf_counter()
    spec = VARIANTS[name][1]
    block, integration = Block(hb=1.0), Integration(n_steps=8, periods=2, window=1,
                                                    max_impacts=100)
    if spec[0] == "run":
        _, embed4, tangent = spec
        forcing = Harmonic(alpha=0.6, omega=1.3, embedded=embed4)
        run_single(SimpleNamespace(block=block, forcing=forcing, integration=integration,
                                   n_steps=8, periods=2, window=1, max_impacts=100,
                                   record_stride=1, lyapunov=tangent, phi=0.0,
                                   y0=(0.1, 0.0, 0.0, 1.0)))
    else:
        par = pack(block, Harmonic(alpha=0.6, omega=1.3), 0.0, integration, 8, 1e-9)
        ipar = settings(8, 2, 100, 1, pmax=1)
        run_chunk(spec[1], np.array([[0.1, 0.0, 0.0, 1.0]]), par[None, :], ipar,
                  np.array([1e-6, 1e-2]), 1, 1)
    return _time.perf_counter() - t0


def compile_kernels(names=COMMON, *, processes=None, progress=None):
    """Compile the variants ``names`` into numba's cache, ``processes`` at a time (default: as
    many as cores; numba's cache is safe across processes), so that later runs only load them.
    ``progress(done, total, name, seconds)`` hears of each. Returns ``{name: seconds}``."""
    import concurrent.futures as cf
    import multiprocessing
    import os

    names = list(names)
    for n in names:
        if n not in VARIANTS:
            raise ValueError(f"kernel variant must be one of {', '.join(VARIANTS)} (got {n!r})")
    processes = processes or min(len(names), os.cpu_count() or 1)
    out = {}
    if processes <= 1:
        for i, n in enumerate(names):
            out[n] = compile_variant(n)
            if progress:
                progress(i + 1, len(names), n, out[n])
        return out
    ctx = multiprocessing.get_context("spawn")
    with cf.ProcessPoolExecutor(max_workers=processes, mp_context=ctx) as ex:
        futures = {ex.submit(compile_variant, n): n for n in names}
        for i, f in enumerate(cf.as_completed(futures)):
            n = futures[f]
            out[n] = f.result()
            if progress:
                progress(i + 1, len(names), n, out[n])
    # this process loads them from the cache it may use next
    return out
