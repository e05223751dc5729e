"""Behaviours, α sweeps (bifurcation diagrams) and basins of attraction.

Three tiers (STYLE.md 1): a serial compiled worker runs one cell (one initial state, one
parameter set) and classifies it; compiled kernels, ``parallel=True``, run a whole grid with
``prange`` over cells, each iteration with private scratch writing only its own row of the
outputs, so results do not depend on the number of threads; the public functions
:func:`sweep` and :func:`basin` check inputs, call the kernels chunk by chunk (progress is shown
between chunks) and wrap the arrays.

Classification (SPEC.md §6), from the stroboscopic samples ``x_k = (theta, theta')`` at ``kT``
and ``kT + T/2`` over the asymptotic window:

- ``overturn``: the run stopped by overturning; ``rest``: it came to rest for good
  (``alpha omega^2 <= cot(thc)`` once at rest);
- period ``p``: the smallest ``p <= pmax`` with ``|x_{k+p} - x_k| <= tol * S`` for every sample
  of the window (both components, both sampling instants) and the same number of impacts in
  periods ``p`` apart, where ``S`` is the largest ``|theta|, |theta'|`` of the window's samples
  (so the tolerance is relative to the orbit's size); at least two repetitions are required;
- ``symmetric``: period 1 and ``x(kT + T/2) = -x(kT)`` to the same tolerance; ``asymmetric``:
  period 1 otherwise; ``multiperiodic``: period ``p >= 2``;
- ``chaotic``: no period and ``lambda1 > lam_tol``; ``aperiodic``: no period, and ``lambda1``
  not computed or ``<= lam_tol``;
- ``unresolved``: the run hit the impact bound (never silently relabelled).

Early stopping (on by default): a bounded run stops as soon as its last ``settle_reps * p``
periods repeat to ``settle_tol`` (much tighter than ``tol``), see
:func:`rockjit.integrate.settled_period`; the class is then taken on that stretch. The full-length
mode stays available with ``early_stop=False``.
"""

from __future__ import annotations

import functools
import math
from contextlib import contextmanager
from dataclasses import dataclass, field

import numba
import numpy as np
from numba import prange

from . import chunks
from . import integrate as ig
from ._jit import jit
from .model import Block
from .simulate import Z0_STUDY, _int, check_step, steps_per_period, _real, check_settings, forcing_phase
from .simulate import pack

__all__ = ["BEHAVIOURS", "GRID_N", "BasinResult", "PlaneResult", "SweepResult", "basin",
           "classify_result", "plane",
           "sweep"]

BEHAVIOURS = ("overturn", "rest", "symmetric", "asymmetric", "multiperiodic", "chaotic",
              "aperiodic", "unresolved")
OVERTURN, REST, SYMMETRIC, ASYMMETRIC, MULTIPERIODIC, CHAOTIC, APERIODIC, UNRESOLVED = range(8)

#: Steps per period of sweeps, basins and planes: they need labels and lambda_max, not 1e-10
#: event times. On the study's four basins and its 501-amplitude sweep, N = 64 gives the labels
#: of N = 256 in every cell (benchmarks/README.md, "Grid resolution"). Raised like DEFAULT_N
#: when the forcing is slow (MAX_STEP).
GRID_N = 64

#: Defaults of the classification (documented in the module docstring and the README).
TOL = 1e-6
PMAX = 16
LAM_TOL = 1e-2
SETTLE_TOL = 1e-9
SETTLE_REPS = 10

# layout of the classification settings ``cpar`` (float)
C_TOL, C_LAMTOL = range(2)
# layout of a cell's scalar results ``res`` (float)
R_LABEL, R_PERIOD, R_LAM1, R_LAM2, R_T, R_NIMP, R_K0, R_K1, R_STATUS = range(9)
N_RES = 9


@jit
def find_period(strobe, half, per_imp, k0, k1, tol, pmax):
    """Smallest period ``p <= pmax`` of the samples ``k0..k1`` (see the module docstring)."""
    scale = 0.0
    for j in range(k0, k1 + 1):
        for c in range(2):
            scale = max(scale, abs(strobe[j, c]))
            if j < k1:
                scale = max(scale, abs(half[j, c]))
    lim = tol * scale + 1e-300
    for p in range(1, pmax + 1):
        if k1 - k0 < 2 * p:
            return 0, lim
        ok = True
        for j in range(k0 + p, k1 + 1):
            if j >= 1 and j - p >= 1 and \
                    per_imp[j] - per_imp[j - 1] != per_imp[j - p] - per_imp[j - p - 1]:
                ok = False
                break
            for c in range(2):
                if abs(strobe[j, c] - strobe[j - p, c]) > lim:
                    ok = False
                if j < k1 and abs(half[j, c] - half[j - p, c]) > lim:
                    ok = False
            if not ok:
                break
        if ok:
            return p, lim
    return 0, lim


@jit
def classify(strobe, half, per_imp, k0, k1, lam1, have_lam, tol, pmax, lam_tol):
    """Behaviour code and period of a bounded run from its samples ``k0..k1``."""
    p, lim = find_period(strobe, half, per_imp, k0, k1, tol, pmax)
    if p == 1:
        for j in range(k0, k1):
            for c in range(2):
                if abs(half[j, c] + strobe[j, c]) > lim:
                    return ASYMMETRIC, 1
        return SYMMETRIC, 1
    if p >= 2:
        return MULTIPERIODIC, p
    if have_lam and lam1 > lam_tol:
        return CHAOTIC, 0
    return APERIODIC, 0


@jit
def lam_between(lam_run, k0, k1):
    """Exponents averaged over ``[k0 T, k1 T]`` from the running estimates at ``kT``.

    ``lam_run[k] = S(kT) / (kT)`` with ``S`` the accumulated log-stretch, so
    ``(lam_run[k1] k1 - lam_run[k0] k0) / (k1 - k0)`` is the growth rate per unit time.
    """
    if k1 <= k0:
        return math.nan, math.nan
    if lam_run[k1, 0] == -math.inf:  # the tangent vectors collapsed (an impact with e = 0)
        return -math.inf, -math.inf
    l1 = (lam_run[k1, 0] * k1 - lam_run[k0, 0] * k0) / (k1 - k0)
    l2 = (lam_run[k1, 1] * k1 - lam_run[k0, 1] * k0) / (k1 - k0)
    return l1, l2


@jit
def _cell(TANGENT, y0, side0, par, ipar, cpar, strobe, half, impacts, traj, lam_run, per_imp,
         iout, fout, res):
    """Run one cell and classify it; scalar results go to ``res``."""
    status = ig._run(False, TANGENT, False, y0, side0, par, ipar, strobe, half, impacts, traj,
                     lam_run, per_imp, iout, fout)
    k1 = iout[ig.O_NSTROBE] - 1
    if status == ig.SETTLED:
        p = iout[ig.O_PERIOD]
        # exactly the samples settled_period compared: (k1 - reps p - p, k1]
        k0 = max(0, k1 - ipar[ig.I_SETTLE] * p - p + 1)
    else:
        k0 = ipar[ig.I_WINDOW]
    lam1 = math.nan
    lam2 = math.nan
    if TANGENT:
        la, lb = lam_between(lam_run, k0, k1)
        lam1 = max(la, lb)  # sorted: lambda1 >= lambda2 (see rockjit.simulate)
        lam2 = min(la, lb)
    label = UNRESOLVED
    period = 0
    if status == ig.OVERTURNED:
        label = OVERTURN
    elif status == ig.REST:
        label = REST
        lam1 = -math.inf
        lam2 = -math.inf
    elif status == ig.DONE or status == ig.SETTLED:
        label, period = classify(strobe, half, per_imp, k0, k1, lam1, TANGENT,
                                 cpar[C_TOL], ipar[ig.I_PMAX], cpar[C_LAMTOL])
    res[R_LABEL] = label
    res[R_PERIOD] = period
    res[R_LAM1] = lam1
    res[R_LAM2] = lam2
    res[R_T] = fout[ig.F_T]
    res[R_NIMP] = iout[ig.O_IMPACTS]
    res[R_K0] = k0
    res[R_K1] = k1
    res[R_STATUS] = status



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
        strobe = np.zeros((periods + 1, 4))
        half = np.zeros((periods + 1, 4))
        impacts = np.zeros((cap, 3))
        traj = np.zeros((1, 5))
        lam_run = np.zeros((periods + 1 if TANGENT else 1, 2))
        per_imp = np.zeros(periods + 1, dtype=np.int64)
        iout = np.zeros(ig.N_IOUT, dtype=np.int64)
        fout = np.zeros(ig.N_FOUT)
        y0 = y0s[i]
        side0 = 0
        if y0[0] > 0.0 or (y0[0] == 0.0 and y0[1] > 0.0):
            side0 = 1
        elif y0[0] < 0.0 or (y0[0] == 0.0 and y0[1] < 0.0):
            side0 = -1
        _cell(TANGENT, y0, side0, par, ipar, cpar, strobe, half, impacts, traj, lam_run, per_imp,
             iout, fout, res[i])
        k0 = int(res[i, R_K0])
        k1 = int(res[i, R_K1])
        lab = int(res[i, R_LABEL])
        bounded = lab != OVERTURN and lab != REST and lab != UNRESOLVED
        if n_pts > 0:
            m = 0
            if bounded:
                for k in range(max(k0, k1 - n_pts + 1), k1 + 1):
                    pts[i, m, 0] = strobe[k, 0]
                    pts[i, m, 1] = strobe[k, 1]
                    m += 1
            n_got[i] = m
        if n_imp_pts > 0:
            m = 0
            if bounded:
                nimp = iout[ig.O_IMPACTS]
                t_from = k0 * T
                first = max(0, nimp - cap)
                for q in range(first, nimp):
                    row = q % cap
                    if impacts[row, 0] >= t_from:
                        tt = impacts[row, 0]
                        imp_pts[i, m, 0] = tt - T * math.floor(tt / T)
                        imp_pts[i, m, 1] = impacts[row, 1]
                        m += 1
            n_imp_got[i] = m



@functools.lru_cache(maxsize=None)
def _kernel(tangent):
    """The grid kernel with or without tangent vectors (a thin closure forwarding the flag as a
    compile-time literal, so that the module-level kernels are specialised and cached)."""
    TANGENT = bool(tangent)

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
        threads = _int("threads", threads, 1, numba.config.NUMBA_NUM_THREADS)
        numba.set_num_threads(threads)
    old_chunk = numba.get_parallel_chunksize()
    numba.set_parallel_chunksize(1)  # cells differ wildly in cost: balance dynamically
    try:
        yield
    finally:
        numba.set_parallel_chunksize(old_chunk)
        numba.set_num_threads(old)


def run_chunk(tangent, y0s, pars, ipar, cpar, n_pts, n_imp_pts, threads=None):
    """Run the grid kernel on one chunk of cells; returns its outputs by name.

    The unit of work of :func:`rockjit.chunks.run_chunks`, in this process or on a Dask worker.
    """
    n = y0s.shape[0]
    out = dict(res=np.zeros((n, N_RES)), pts=np.full((n, max(n_pts, 1), 2), np.nan),
               imp=np.full((n, max(n_imp_pts, 1), 2), np.nan),
               n_got=np.zeros(n, dtype=np.int64), n_imp_got=np.zeros(n, dtype=np.int64))
    with _threads(threads):
        _kernel(tangent)(np.ascontiguousarray(y0s), np.ascontiguousarray(pars), ipar, cpar,
                         n_pts, n_imp_pts, out["res"], out["pts"], out["imp"], out["n_got"],
                         out["n_imp_got"])
    return out


def _run_grid(y0s, pars, ipar, cpar, *, tangent, n_pts, n_imp_pts, threads, progress, label,
              chunk=None, client=None, store=None):
    """All cells through :func:`run_chunk`, chunk by chunk (progress between chunks)."""
    n = y0s.shape[0]
    chunk = max(64, -(-n // 20)) if chunk is None else _int("chunk", chunk, 1)
    outputs = dict(res=np.zeros((n, N_RES)), pts=np.full((n, max(n_pts, 1), 2), np.nan),
                   imp=np.full((n, max(n_imp_pts, 1), 2), np.nan),
                   n_got=np.zeros(n, dtype=np.int64), n_imp_got=np.zeros(n, dtype=np.int64))
    cs = None
    if store is not None:
        key = chunks.fingerprint((y0s, pars, ipar, cpar),
                                 dict(tangent=bool(tangent), n_pts=n_pts, n_imp_pts=n_imp_pts))
        cs = chunks.ChunkStore(store, key, n, chunk)
    chunks.run_chunks(run_chunk, (bool(tangent), y0s, pars, ipar, cpar, n_pts, n_imp_pts,
                                  threads), n, chunk, outputs, client=client, store=cs,
                      progress=progress, label=label)
    return (outputs["res"], outputs["pts"], outputs["imp"], outputs["n_got"],
            outputs["n_imp_got"])


def _settings(block, phi, periods, n_steps, window, early_stop, tol, pmax, lam_tol,
              max_impacts, settle_tol, settle_reps):
    if n_steps is None:
        n_steps = steps_per_period(block.period, GRID_N)
    else:
        check_step(block.period, _int("n_steps", n_steps, 8))
    periods, n_steps, max_impacts, w0, _ = check_settings(periods, n_steps, max_impacts,
                                                          window, None)
    pmax = _int("pmax", pmax, 1)
    settle_reps = _int("settle_reps", settle_reps, 2)
    tol = _real("tol", tol)
    if not 0 < tol < 1:
        raise ValueError(f"tol must be in (0, 1) (got {tol})")
    settle_tol = _real("settle_tol", settle_tol)
    if not 0 < settle_tol <= tol:
        raise ValueError(f"settle_tol must be in (0, tol] (got {settle_tol})")
    par = pack(block, phi, n_steps)
    par[ig.P_SETTLE_TOL] = settle_tol
    ipar = np.zeros(ig.N_IPAR, dtype=np.int64)
    ipar[ig.I_N] = n_steps
    ipar[ig.I_PERIODS] = periods
    ipar[ig.I_MAXIMP] = max_impacts
    ipar[ig.I_STRIDE] = 1
    ipar[ig.I_WINDOW] = w0
    ipar[ig.I_SETTLE] = settle_reps if early_stop else 0
    ipar[ig.I_QR] = n_steps // 2
    ipar[ig.I_PMAX] = pmax
    cpar = np.array([tol, _real("lam_tol", lam_tol)])
    return par, ipar, cpar, dict(periods=periods, n_steps=n_steps, window=w0,
                                 early_stop=bool(early_stop), tol=tol, pmax=pmax,
                                 lam_tol=float(cpar[1]), settle_tol=settle_tol,
                                 settle_reps=settle_reps, max_impacts=max_impacts)


def _names_array():
    return np.array(BEHAVIOURS)


def fractions(label):
    """Percentage of cells per behaviour name (every name present, zeros included)."""
    label = np.asarray(label)
    n = label.size
    return {name: (100.0 * np.count_nonzero(label == code) / n if n else 0.0)
            for code, name in enumerate(BEHAVIOURS)}


@dataclass
class SweepResult:
    """An α sweep: one run per forcing amplitude, all from the same initial state.

    Attributes
    ----------
    alpha : ndarray, shape (n,)
    label : ndarray of int, shape (n,)
        Behaviour codes; ``names[label]`` gives the names (:data:`BEHAVIOURS`).
    period : ndarray of int, shape (n,)
        Period in forcing periods (0 when none).
    lambda_max : ndarray, shape (n,)
        ``lambda1`` over the classified stretch (``nan`` when not computed or overturned,
        ``-inf`` for rest).
    strobe : ndarray, shape (n, w, 2)
        ``(theta, theta')`` at ``t = kT`` over the classified stretch (``nan``-padded).
    impact_section : ndarray, shape (n, m, 2)
        ``(t mod T, theta'-)`` of the impacts over the classified stretch (``nan``-padded).
    t_end : ndarray, shape (n,)
        Time each run stopped (early stop, overturn, rest or the end).
    """

    alpha: np.ndarray
    label: np.ndarray
    period: np.ndarray
    lambda_max: np.ndarray
    strobe: np.ndarray
    impact_section: np.ndarray
    t_end: np.ndarray
    block: Block
    settings: dict = field(default_factory=dict)
    names: np.ndarray = field(default_factory=_names_array)

    def fractions(self):
        return fractions(self.label)


@dataclass
class BasinResult:
    """A basin of attraction over ``(theta0, theta0')`` at a fixed forcing phase.

    ``label[i, j]`` belongs to ``theta0[i]``, ``dtheta0[j]``.
    """

    theta0: np.ndarray
    dtheta0: np.ndarray
    label: np.ndarray
    period: np.ndarray
    lambda_max: np.ndarray | None
    t_end: np.ndarray
    block: Block
    settings: dict = field(default_factory=dict)
    names: np.ndarray = field(default_factory=_names_array)

    def fractions(self):
        return fractions(self.label)


def _block(hb, alpha, omega, law, e, xi):
    kw = dict(hb=hb, alpha=alpha, omega=omega, law=law, e=e)
    if xi is not None:
        kw["xi"] = xi
    return Block(**kw)


def alpha_grid(alpha_range, alpha_step):
    """``alpha_range[0], alpha_range[0] + step, ..., alpha_range[1]`` (end included)."""
    try:
        a0, a1 = (float(v) for v in alpha_range)
    except (TypeError, ValueError):
        raise ValueError(f"alpha_range must be two numbers (got {alpha_range!r})") from None
    step = _real("alpha_step", alpha_step)
    if not (math.isfinite(a0) and math.isfinite(a1)) or a0 < 0 or a1 < a0:
        raise ValueError(f"alpha_range must satisfy 0 <= start <= end (got {a0}, {a1})")
    if step <= 0:
        raise ValueError(f"alpha_step must be > 0 (got {step})")
    n = int(math.floor((a1 - a0) / step + 1e-9)) + 1
    return a0 + step * np.arange(n)


def sweep(hb, omega, alphas=None, *, law=None, e=None, xi=None, alpha_range=None,
          alpha_step=0.001, z0=Z0_STUDY, periods=500, n_steps=None, window=None,
          lyapunov=True, early_stop=True, threads=None, progress=False, tol=TOL, pmax=PMAX,
          lam_tol=LAM_TOL, max_impacts=100_000, settle_tol=SETTLE_TOL,
          settle_reps=SETTLE_REPS, n_points=None, n_impact_points=400, client=None,
          store=None, chunk=None) -> SweepResult:
    """Bifurcation sweep over the forcing amplitude ``alpha`` (SPEC.md §7).

    Parameters
    ----------
    hb, omega : float
        Slenderness and forcing frequency.
    alphas : array_like, optional
        The amplitudes; or give ``alpha_range=(start, end)`` and ``alpha_step``.
    law, e, xi :
        As in :func:`rockjit.simulate`.
    z0 : sequence of 4 floats
        ``(theta0, theta0', r0, s0)``, default the study's.
    periods, n_steps, window :
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
        Classification settings (module docstring).
    n_points : int, optional
        Stroboscopic samples kept per alpha (default the window length).
    n_impact_points : int
        Impact-section points kept per alpha.
    client : dask.distributed.Client, optional
        Run the chunks of cells on this cluster (:mod:`rockjit.chunks`).
    store : path, optional
        Directory for finished chunks: a rerun with the same inputs computes only what is
        missing.
    chunk : int, optional
        Cells per chunk (the unit of progress, of Dask tasks and of resumption); default
        about a twentieth of the grid, at least 64.
    """
    if alphas is None:
        if alpha_range is None:
            raise ValueError("give alphas or alpha_range")
        alphas = alpha_grid(alpha_range, alpha_step)
    alphas = np.atleast_1d(np.asarray(alphas, dtype=float))
    if alphas.ndim != 1 or alphas.size == 0:
        raise ValueError("alphas must be a non-empty 1-D sequence")
    if not np.all(np.isfinite(alphas)) or np.any(alphas < 0):
        raise ValueError("alphas must be finite and >= 0")
    block = _block(hb, float(alphas[0]), omega, law, e, xi)
    z = np.asarray(z0, dtype=float).ravel()
    if z.shape != (4,) or not np.all(np.isfinite(z)):
        raise ValueError("z0 must be 4 finite numbers (theta, theta', r, s)")
    phi, r0, s0 = forcing_phase(None, z[2], z[3], "closed")
    par, ipar, cpar, settings = _settings(block, phi, periods, n_steps, window, early_stop,
                                          tol, pmax, lam_tol, max_impacts, settle_tol,
                                          settle_reps)
    n = alphas.size
    w = settings["periods"] - settings["window"] + 1
    n_points = w if n_points is None else _int("n_points", n_points, 1)
    n_impact_points = _int("n_impact_points", n_impact_points, 0)
    y0s = np.tile(np.array([z[0], z[1], r0, s0]), (n, 1))
    pars = np.tile(par, (n, 1))
    pars[:, ig.P_AW2] = alphas * block.omega**2
    res, pts, imp, n_got, n_imp_got = _run_grid(
        y0s, pars, ipar, cpar, tangent=lyapunov, n_pts=n_points,
        n_imp_pts=n_impact_points, threads=threads, progress=progress, label="sweep",
        client=client, store=store, chunk=chunk)
    settings.update(z0=tuple(z), lyapunov=bool(lyapunov), law=block.law,
                    restitution=block.restitution)
    return SweepResult(alpha=alphas, label=res[:, R_LABEL].astype(np.int64),
                       period=res[:, R_PERIOD].astype(np.int64), lambda_max=res[:, R_LAM1],
                       strobe=pts, impact_section=imp, t_end=res[:, R_T], block=block,
                       settings=settings)


def basin(hb, alpha, omega, *, law=None, e=None, xi=None, grid=100, theta_range=(-1.0, 1.0),
          dtheta_range=(-1.0, 1.0), r0=None, s0=None, phase=None, periods=500,
          n_steps=None, window=None, lyapunov=False, early_stop=True, threads=None,
          progress=False, tol=TOL, pmax=PMAX, lam_tol=LAM_TOL, max_impacts=100_000,
          settle_tol=SETTLE_TOL, settle_reps=SETTLE_REPS, client=None,
          store=None, chunk=None) -> BasinResult:
    """Basin of attraction over ``(theta0, theta0')`` on a ``grid x grid`` lattice.

    The forcing phase is fixed (default ``(r0, s0) = (0, 1)``, SPEC.md §7). ``label[i, j]``
    belongs to ``theta0[i]``, ``dtheta0[j]``. Other parameters (``client`` and ``store``
    included) as in :func:`sweep`.
    """
    block = _block(hb, alpha, omega, law, e, xi)
    grid = _int("grid", grid, 1)
    rngs = []
    for name, rng in (("theta_range", theta_range), ("dtheta_range", dtheta_range)):
        try:
            lo, hi = (float(v) for v in rng)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be two numbers (got {rng!r})") from None
        if not (math.isfinite(lo) and math.isfinite(hi)) or hi < lo:
            raise ValueError(f"{name} must satisfy start <= end, both finite (got {lo}, {hi})")
        rngs.append((lo, hi))
    if max(abs(rngs[0][0]), abs(rngs[0][1])) >= block.theta_over:
        raise ValueError(f"theta_range must lie inside (-theta_over, theta_over) = "
                         f"(-{block.theta_over:.6g}, {block.theta_over:.6g}) (got {rngs[0]})")
    phi, r0, s0 = forcing_phase(phase, r0, s0, "closed")
    par, ipar, cpar, settings = _settings(block, phi, periods, n_steps, window, early_stop,
                                          tol, pmax, lam_tol, max_impacts, settle_tol,
                                          settle_reps)
    th = np.linspace(*rngs[0], grid)
    dth = np.linspace(*rngs[1], grid)
    TH, DTH = np.meshgrid(th, dth, indexing="ij")
    y0s = np.stack([TH.ravel(), DTH.ravel(), np.full(TH.size, r0), np.full(TH.size, s0)], 1)
    pars = np.tile(par, (TH.size, 1))
    res, *_ = _run_grid(y0s, pars, ipar, cpar, tangent=lyapunov, n_pts=0, n_imp_pts=0,
                        threads=threads, progress=progress, label="basin", client=client,
                        store=store, chunk=chunk)
    settings.update(r0=r0, s0=s0, phase=phi, lyapunov=bool(lyapunov), law=block.law,
                    restitution=block.restitution)
    shape = (grid, grid)
    return BasinResult(theta0=th, dtheta0=dth,
                       label=res[:, R_LABEL].astype(np.int64).reshape(shape),
                       period=res[:, R_PERIOD].astype(np.int64).reshape(shape),
                       lambda_max=res[:, R_LAM1].reshape(shape) if lyapunov else None,
                       t_end=res[:, R_T].reshape(shape), block=block, settings=settings)


def classify_result(result, *, tol=TOL, pmax=PMAX, lam_tol=LAM_TOL):
    """Behaviour name and period of a :class:`rockjit.Result` (window of the run).

    Uses the same compiled classifier as the sweeps and basins on the result's stroboscopic
    samples from ``window`` on. Returns ``(name, period)``.
    """
    if result.status == "overturned":
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


@dataclass
class PlaneResult:
    """Behaviours over the forcing plane ``(alpha, omega)`` from one or more initial states.

    ``label[m, i, j]`` belongs to initial state ``z0[m]``, ``alpha[i]``, ``omega[j]``.
    """

    alpha: np.ndarray
    omega: np.ndarray
    z0: np.ndarray
    label: np.ndarray
    period: np.ndarray
    lambda_max: np.ndarray
    t_end: np.ndarray
    block: Block
    settings: dict = field(default_factory=dict)
    names: np.ndarray = field(default_factory=_names_array)

    def fractions(self):
        return fractions(self.label)


def _range(name, rng, lo_open=False):
    try:
        a, b = (float(v) for v in rng)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be two numbers (got {rng!r})") from None
    ok = math.isfinite(a) and math.isfinite(b) and b >= a and (a > 0 if lo_open else a >= 0)
    if not ok:
        cond = "0 < start <= end" if lo_open else "0 <= start <= end"
        raise ValueError(f"{name} must satisfy {cond} (got {a}, {b})")
    return a, b


def plane(hb, alpha_range, omega_range, *, grid=(50, 50), law=None, e=None, xi=None,
          z0=Z0_STUDY, periods=500, n_steps=None, window=None, lyapunov=True,
          early_stop=True, threads=None, progress=False, tol=TOL, pmax=PMAX, lam_tol=LAM_TOL,
          max_impacts=100_000, settle_tol=SETTLE_TOL, settle_reps=SETTLE_REPS, client=None,
          store=None, chunk=None) -> PlaneResult:
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
    a0, a1 = _range("alpha_range", alpha_range)
    w0, w1 = _range("omega_range", omega_range, lo_open=True)
    try:
        na, nw = (int(v) for v in grid)
    except (TypeError, ValueError):
        raise ValueError(f"grid must be two integers (got {grid!r})") from None
    na = _int("grid", na, 1)
    nw = _int("grid", nw, 1)
    block = _block(hb, a0, w0, law, e, xi)
    z = np.atleast_2d(np.asarray(z0, dtype=float))
    if z.ndim != 2 or z.shape[1] != 4 or z.shape[0] == 0 or not np.all(np.isfinite(z)):
        raise ValueError("z0 must be 4 finite numbers (theta, theta', r, s) or m rows of them")
    phis = [forcing_phase(None, r, s, "closed")[0] for r, s in z[:, 2:]]
    par, ipar, cpar, settings = _settings(block, phis[0], periods, n_steps, window, early_stop,
                                          tol, pmax, lam_tol, max_impacts, settle_tol,
                                          settle_reps)
    alphas = np.linspace(a0, a1, na)
    omegas = np.linspace(w0, w1, nw)
    M = z.shape[0]
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
    res, *_ = _run_grid(y0s, pars, ipar, cpar, tangent=lyapunov, n_pts=0, n_imp_pts=0,
                        threads=threads, progress=progress, label="plane", client=client,
                        store=store, chunk=chunk)
    shape = (M, na, nw)
    settings.update(lyapunov=bool(lyapunov), law=block.law, restitution=block.restitution)
    return PlaneResult(alpha=alphas, omega=omegas, z0=z,
                       label=res[:, R_LABEL].astype(np.int64).reshape(shape),
                       period=res[:, R_PERIOD].astype(np.int64).reshape(shape),
                       lambda_max=res[:, R_LAM1].reshape(shape),
                       t_end=res[:, R_T].reshape(shape), block=block, settings=settings)
