"""The compiled hybrid integrator: fixed-step Dormand–Prince 5(4) with located impacts.

One period of the forcing is cut into ``N`` equal steps ``h = T/N``, so the stroboscopic samples
``t = kT`` and ``kT + T/2`` fall on the grid. Per step (docs/theory/integrator.md):

1. take a Dormand–Prince step on the current corner (the field of a corner extends smoothly past
   ``theta = 0``, so the step can overshoot the impact);
2. detect an event: a sign change of ``theta`` (also the grazing case in which ``theta`` dips
   through 0 and comes back within the step, and the case that starts on 0 just after an impact),
   ``|theta|`` reaching the overturning threshold, or, at rest, ``|f|`` reaching ``cot(thc)``;
3. locate the event on the step's own data: Hermite polynomials of degree 7 through theta and
   its first three derivatives at the step's ends (theta' through its first three), the root
   polished by Newton's iteration on them, the state there taken from them when their error
   estimate allows (:func:`locate_interp`); otherwise, or with the embedding, a genuine
   5th-order step of the event's length from the step's start gives the state there, and one
   more Newton correction (below 1e-8 h) carries it along the field (:func:`locate_step`);
4. jump (impact map, saltation of the tangent vectors), refresh the first stage, record the
   event, and finish the step from the event time to the grid point (again with detection).

Where each piece lives: the tableau and the step's table in :mod:`~rockjit._engine.tableau`,
the stage chain (written once, rendered for each step) in :mod:`~rockjit._engine.stages`, the
step of the block, the oscillator and the tangent matrix in :mod:`~rockjit._engine.step`,
detection and location of events in :mod:`~rockjit._engine.events`, the arguments' layout and
the status codes in :mod:`~rockjit._engine.layout`; this module drives them (the loop over the
grid, impacts, samples, the exponents' renormalisation). A step is six stages in a chain, each
waiting for the one before, so its cost is the chain's latency more than its arithmetic. The
step's and the events' pieces are inlined into :func:`drive` by LLVM (they are marked
``alwaysinline``: :func:`rockjit._jit.jit`), which is compiled without numba's reference
counting: out of line, each call would pass its dozen arrays as seven scalars apiece.

The state lives in one array ``y``: ``theta, theta'``, then ``r, s`` when the oscillator
embedding is integrated, then the 2×2 tangent matrix (column-major) when Lyapunov exponents are
asked for. Which of these exist is decided at compile time by :func:`build`; a run that does not
ask for tangent vectors compiles without them. The compile-time switches
``EMBED4``, ``TANGENT`` (and ``block_step``'s ``SLOPE``) are ``True`` or ``None``, never
``False``, and are tested as ``is not None``: numba prunes a branch before typing it only when
it compares an argument with ``None`` (``numba.core.analysis.dead_branch_prune``), so a run
without tangent vectors or embedding never types, lowers or optimises their code. ``False``
would read as on. Recording a trajectory is the one run-time switch (one test per grid step,
in :func:`grid_point`), which halves the variants to compile.

Kernels never raise; they return the status codes of :mod:`~rockjit._engine.layout`, which
:mod:`rockjit.single` turns into messages.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .._jit import cycles, jit
from .classify import orbit_scale, repeats
from ..laws.impact import restitution_at
from ..model import jump, saltation_at
from ..plugs import harmonic
# the tableau (scipy's names) and the step's table, the layout, the step and the events: each
# a module of its own, named here too (the kernels' one entry point)
from .tableau import A, B, C, E, N_STAGES, N_TAB, P, step_table, tab_entry  # noqa: F401
from .layout import (RUNNING, DONE, OVERTURNED, REST, MAX_IMPACTS, NONFINITE, SETTLED,  # noqa: F401
                     STATUS_NAMES, Loop, Outputs, Work, P_THC, P_XI, P_E, P_AW2, P_OMEGA, P_PHI,
                     P_COT,
                     P_THOVER, P_REST, P_H, P_SETTLE_TOL, P_LAW, P_LAW_SHAPE, N_PAR, P_STHC,
                     P_CTHC, N_PARW, I_N,
                     I_PERIODS, I_MAXIMP, I_STRIDE, I_WINDOW, I_SETTLE, I_QR, I_PMAX, I_CONTINUE,
                     N_IPAR, O_STATUS, O_STEPS, O_IMPACTS, O_RHS, O_NSTROBE, O_NHALF, O_NTRAJ,
                     O_NREST, O_NREST_WIN, O_SUBSTEPS, O_NIMP_WIN, O_PERIOD, O_NCOL, O_UNCONVERGED,
                     O_RESTEP, N_IOUT, F_T, F_TH, F_S, F_MAXERR, F_LAM1, F_LAM2, F_WINTIME, F_V,
                     F_TOVER, N_FOUT, FT_DF0, FT_DF1, FT_SIN, FT_COS, N_FTAB, EV_NONE, EV_IMPACT,
                     EV_OVERTURN, EV_UPLIFT, BISECT_ITERS, OFF_GRID)
from .step import rhs, block_step, phase_before_grid, forcing_at, rk_step  # noqa: F401
from .events import (turning_point, interp_at, locate_interp, locate, locate_step,  # noqa: F401
                     detect)


def build(embed4: bool = False, tangent: bool = False):
    """Compile (once, then from numba's cache) the integrator for one set of switches.

    Parameters
    ----------
    embed4 : bool
        Integrate the forcing oscillator ``(r, s)`` with the block (docs/theory/model.md) instead of using
        the closed form ``r = sin(omega t + phi)``.
    tangent : bool
        Carry the 2×2 tangent matrix for Lyapunov exponents (docs/theory/exponents.md).

    Returns
    -------
    run : numba dispatcher
        ``run(y0, side0, par, ipar, out)`` with ``out`` an :data:`Outputs`; returns the status
        code (see :func:`drive`). Recording is not a switch here: ``out.traj`` with more than
        one row records the dense trajectory (see :func:`_run`).
    """
    return _build(True if embed4 else None, True if tangent else None)


@jit(nrt=False)
def settled_period(strobe, half, per_imp, k, reps, pmax, tol):
    """Smallest period p <= pmax that the last ``reps * p`` periods repeat, else 0.

    The period test of :func:`rockjit._engine.classify.repeats` on periods ``k - reps p + 1 .. k``,
    relative to the size of the samples from ``k - (reps + 1) p`` on. It also requires the same
    number of impacts in each compared period, so that a transient which happens to be at rest
    at the sampling instants is not taken for a periodic orbit.
    """
    for p in range(1, pmax + 1):
        n = reps * p
        k0 = k - n - p
        if k0 < 0:
            return 0
        lim = tol * orbit_scale(strobe, half, k0, k) + 1e-300
        if repeats(strobe, half, per_imp, k - n + 1, k, p, 0, lim):
            return p
    return 0


@jit(nrt=False)
def forcing_now(EMBED4, t, y, par):
    if EMBED4 is not None:
        return y[2]
    return harmonic.forcing_closed(t, par[P_OMEGA], par[P_PHI])


@jit(nrt=False)
def sample(EMBED4, t, y, par, out):
    out[0] = y[0]
    out[1] = y[1]
    if EMBED4 is not None:
        out[2] = y[2]
        out[3] = y[3]
    else:
        out[2], out[3] = harmonic.phase_at(t, par[P_OMEGA], par[P_PHI])


@jit(nrt=False)
def qr_renormalise(EMBED4, y, lam_sum, in_window, lam_win):
    """Gram–Schmidt on the tangent columns; logs of the stretches are accumulated.

    Returns True if the tangent vectors had collapsed (an impact with ``e = 0`` maps every
    perturbation of the velocity to zero: ``det S = e^2``). The logs would be ``-inf``; they are
    not added, the vectors restart as the identity, and the caller counts the collapse (the
    exponents over a stretch with a collapse are ``-inf``).
    """
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    v00 = y[NS]
    v10 = y[NS + 1]
    v01 = y[NS + 2]
    v11 = y[NS + 3]
    n1 = math.sqrt(v00 * v00 + v10 * v10)
    det = abs(v00 * v11 - v10 * v01)
    if not (n1 > 0.0 and det > 1e-300 * max(n1, 1.0) and math.isfinite(det)):
        reset_tangent(EMBED4, y)
        return True
    q00 = v00 / n1
    q10 = v10 / n1
    p = q00 * v01 + q10 * v11
    w0 = v01 - p * q00
    w1 = v11 - p * q10
    n2 = math.sqrt(w0 * w0 + w1 * w1)
    l1 = math.log(n1)
    l2 = math.log(n2)
    lam_sum[0] += l1
    lam_sum[1] += l2
    if in_window:
        lam_win[0] += l1
        lam_win[1] += l2
    y[NS] = q00
    y[NS + 1] = q10
    y[NS + 2] = w0 / n2
    y[NS + 3] = w1 / n2
    return False


@jit(nrt=False)
def reset_tangent(EMBED4, y):
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    y[NS] = 1.0
    y[NS + 1] = 0.0
    y[NS + 2] = 0.0
    y[NS + 3] = 1.0


@jit(ir_inline=True)
def _run(EMBED4, TANGENT, y0, side0, par_in, ipar, out):
    """One run from ``y0`` on corner ``side0``: the parameters ``par_in`` (``N_PAR``) and
    settings ``ipar`` in, :data:`Outputs` ``out`` filled; returns the status code.

    The work arrays are made here, and the loop itself is compiled without numba's reference
    counting (its helpers are inlined into it, and each inlined array would be counted)."""
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    NY = NS + (4 if TANGENT is not None else 0)  # plus the tangent matrix, column-major
    par = np.zeros(N_PARW)  # the parameters and constants derived from them
    for m in range(N_PAR):
        par[m] = par_in[m]
    par[P_STHC] = math.sin(par_in[P_THC])
    par[P_CTHC] = math.cos(par_in[P_THC])
    states = np.zeros((4, NY))  # y, ytmp, ynew, yev
    w = Work(np.zeros((N_STAGES + 1, NY)), states[0], states[1], states[2], states[3],
             np.zeros(4), np.zeros((N_TAB, N_STAGES + 1)), np.zeros((N_TAB, N_STAGES + 1)),
             np.zeros(N_STAGES + 1), np.zeros(N_STAGES + 1), np.zeros(4),
             np.zeros((ipar[I_N], N_FTAB)))
    # Recording is a run-time switch (a trajectory array of more than one row), not a
    # compile-time one: one compiled loop serves runs with and without it and the grids; its
    # test costs nothing measurable per step.
    record = out.traj.shape[0] > 1
    status = start(EMBED4, TANGENT, y0, side0, par, ipar, out, w)
    return drive(EMBED4, TANGENT, record, status, side0, par, ipar, out, w)


@jit(nrt=False)
def tables(EMBED4, par, ipar, w):
    """The step table of a grid step (``w.tab_h``) and, with the closed-form forcing, the
    forcing table ``w.ftab`` of a period (columns ``FT_*``): the grid repeats, so the forcing at
    stage ``i`` of grid step ``j``, phase ``phi + 2 pi (j + c_i) / N``, is made once per run, as
    the phase at the step's start rotated by the stage's advance ``2 pi c_i / N`` (one sine and
    cosine per grid step)."""
    n_per = ipar[I_N]
    step_table(par[P_OMEGA], par[P_H], w.tab_h)
    if EMBED4 is None:
        aw2 = par[P_AW2]
        aw3 = aw2 * par[P_OMEGA]
        ftab = w.ftab
        for j in range(n_per):
            s0, c0 = harmonic.grid_phase(par[P_PHI], j, n_per)
            ftab[j, FT_SIN] = s0
            ftab[j, FT_COS] = c0
            ftab[j, FT_DF0] = harmonic.slope(aw3, c0)
            for i in range(N_STAGES + 1):
                c = C[i] if i < N_STAGES else 1.0
                sd, cd = harmonic.grid_advance(c, n_per)
                ftab[j, i] = aw2 * harmonic.advance(s0, c0, cd, sd)
                if i == N_STAGES:
                    ftab[j, FT_DF1] = harmonic.slope(aw3, harmonic.advance_slope(s0, c0, cd, sd))


@jit(nrt=False, inline=True)
def start(EMBED4, TANGENT, y0, side0, par, ipar, out, w):
    """Before the first step: the step tables (:func:`tables`), the initial state and its
    samples, the field at the start. Returns the status (overturned already, or running)."""
    tables(EMBED4, par, ipar, w)
    return start_state(EMBED4, TANGENT, y0, side0, par, ipar, out, w)


@jit(nrt=False, inline=True)
def start_state(EMBED4, TANGENT, y0, side0, par, ipar, out, w):
    """:func:`start` less the tables (the lanes keep a lane's tables for its next cell when
    the forcing and the grid are the same)."""
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    y = w.y
    for m in range(NS):
        y[m] = y0[m]
    if TANGENT is not None:
        reset_tangent(EMBED4, y)
    for m in range(N_IOUT):
        out.iout[m] = 0
    sample(EMBED4, 0.0, y, par, out.strobe[0])
    out.iout[O_NSTROBE] = 1
    # the trajectory's first row: every caller's ``traj`` has one (it is read only when recording)
    out.traj[0, 0] = 0.0
    sample(EMBED4, 0.0, y, par, out.traj[0, 1:])
    out.iout[O_NTRAJ] = 1
    if TANGENT is not None:
        for c in range(3):
            out.lam_run[0, c] = 0.0
    out.per_imp[0] = 0
    out.fout[F_TOVER] = math.nan
    status = RUNNING
    if side0 != 0 and side0 * y[0] >= par[P_THOVER]:
        status = OVERTURNED
    if TANGENT is not None and side0 == 0:
        # at rest from the start: every perturbation small enough dies in a Zeno cascade, and
        # the block leaves rest when the forcing alone says (see drive, rest phases)
        out.iout[O_NCOL] = 1
    rhs(EMBED4, forcing_at(0.0, par), y, side0, par, w.K, w.jac, w.trig)
    out.iout[O_RHS] += 1
    return status


@jit(nrt=False, inline=True)
def leave_rest(EMBED4, t, t_grid, hold, y, side, par, w, iout):
    """At rest: is the block lifted before the grid point ``t_grid``?

    Returns ``(action, t, side)``: ``REST_END`` (at rest for good), ``REST_HOLD`` (still at
    rest at ``t_grid``; closed form only, which jumps straight to the uplift instant),
    ``REST_LIFT`` (lifted at the returned ``t`` onto ``side``, field refreshed), or
    ``REST_STEP`` (embedding: take a step at rest and watch the forcing).
    """
    if EMBED4 is None:
        t_up = harmonic.uplift_time(t, par[P_AW2], par[P_COT], par[P_OMEGA], par[P_PHI])
        if t_up == math.inf:
            return REST_END, t, side
        if t_up >= t_grid or hold:
            return REST_HOLD, t_grid, side
        y[0] = 0.0
        y[1] = 0.0
        side = 1 if forcing_now(EMBED4, t_up, y, par) > 0.0 else -1
        rhs(EMBED4, forcing_at(t_up, par), y, side, par, w.K, w.jac, w.trig)
        iout[O_RHS] += 1
        return REST_LIFT, t_up, side
    rad = math.sqrt(y[2] * y[2] + y[3] * y[3])
    if par[P_AW2] * harmonic.peak_after(rad) <= par[P_COT]:
        return REST_END, t, side
    if not hold and par[P_AW2] * abs(y[2]) > par[P_COT]:
        side = 1 if y[2] > 0.0 else -1
        rhs(EMBED4, forcing_at(t, par), y, side, par, w.K, w.jac, w.trig)
        iout[O_RHS] += 1
        return REST_LIFT, t, side
    return REST_STEP, t, side


@jit(nrt=False, inline=True)
def accept(EMBED4, TANGENT, side, hh, max_err, w):
    """The step just taken had no event: its error estimate, the state at its end, and its
    last stage as the next step's first (first same as last). Returns the largest error
    estimate so far.

    It takes the compile-time switches, not the state's sizes: with the sizes known when it is
    compiled, its copies are straight loads and stores (with sizes unknown, LLVM vectorises
    them behind run-time overlap checks, a slower step)."""
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    NY = NS + (4 if TANGENT is not None else 0)  # plus the tangent matrix, column-major
    K = w.K
    if side != 0:
        e0 = 0.0
        e1 = 0.0
        for i in range(N_STAGES + 1):
            e0 += E[i] * K[i, 0]
            e1 += E[i] * K[i, 1]
        err = hh * max(abs(e0), abs(e1))
        if err > max_err:
            max_err = err
    for m in range(NY):
        w.y[m] = w.ynew[m]
    for m in range(NS):  # first same as last (the tangent rows are redone)
        K[0, m] = K[N_STAGES, m]
    w.jac[0] = w.jac[N_STAGES]
    w.trig[0] = w.trig[2]
    w.trig[1] = w.trig[3]
    return max_err


@jit(nrt=False, inline=True)
def impact(EMBED4, TANGENT, t, r, t_lift, side, n_imp, in_window, par, out, w):
    """The jump at an impact (docs/theory/impacts.md), the saltation of the tangent vectors
    (docs/theory/exponents.md), the impact's record, and the Zeno cut-off. ``r``: the closed-form forcing
    ``sin(omega t + phi)`` at ``t`` (ignored with the embedding).

    Returns ``(side, n_imp, rests, hold)``: the new corner (0 if the block came to rest), the
    impact count, whether a rest phase began, and whether it began within rounding of the
    latest uplift (then it is held to the grid point, see :func:`grid_step`).
    """
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    y = w.y
    dth_m = y[1]
    e, e_slope = restitution_at(int(par[P_LAW]), abs(dth_m), par[P_E], par[P_LAW_SHAPE])
    dth_p = jump(dth_m, e)
    if TANGENT is not None:
        if dth_m != 0.0:
            s10 = saltation_at(dth_m, par[P_AW2] * (y[2] if EMBED4 is not None else r), side,
                               par[P_THC], par[P_XI], e, e_slope)
        else:
            s10 = 0.0
        for c in range(2):
            v0 = y[NS + 2 * c]
            v1 = y[NS + 2 * c + 1]
            y[NS + 2 * c] = e * v0
            y[NS + 2 * c + 1] = s10 * v0 + e_slope * v1
    y[0] = 0.0
    y[1] = dth_p
    side = -side
    impacts = out.impacts
    q = n_imp % impacts.shape[0]  # a ring: the latest impacts are kept
    impacts[q, 0] = t
    impacts[q, 1] = dth_m
    impacts[q, 2] = dth_p
    n_imp += 1
    if in_window:
        out.iout[O_NIMP_WIN] += 1
    rests = False
    hold = False
    if abs(dth_p) < par[P_REST] or dth_p == 0.0:
        # Zeno: the impacts would accumulate; the block is at rest from here
        y[1] = 0.0
        side = 0
        rests = True
        hold = t - t_lift <= 1e-9 * par[P_H]
        out.iout[O_NREST] += 1
        if in_window:
            out.iout[O_NREST_WIN] += 1
    rhs(EMBED4, r, y, side, par, w.K, w.jac, w.trig)
    out.iout[O_RHS] += 1
    return side, n_imp, rests, hold


@jit(nrt=False, inline=True)
def grid_point(EMBED4, TANGENT, record, t, step, side, n_imp, n_col, in_window, ipar, par,
               out, w, j_per, k_per, j_qr, j_rec):
    """Bookkeeping at the end of grid step ``step`` (1-based count): the tangent vectors'
    renormalisation, the stroboscopic samples at ``kT`` and ``kT + T/2``, the early stop, the
    recorded trajectory.

    Returns ``(status, j_per, k_per, j_qr, j_rec, collapsed)``: ``collapsed`` says the tangent
    vectors collapsed at the renormalisation (counted by the caller).
    """
    y = w.y
    n_per = ipar[I_N]
    status = RUNNING
    collapsed = False
    if TANGENT is not None:
        j_qr += 1
        if j_qr == ipar[I_QR]:
            j_qr = 0
            if side != 0:
                collapsed = qr_renormalise(EMBED4, y, w.lam[0:2], in_window, w.lam[2:4])
                # (the first stage's tangent rows are computed afresh by every step)
    j_per += 1
    if j_per == n_per:
        j_per = 0
        k_per += 1
        sample(EMBED4, t, y, par, out.strobe[k_per])
        out.iout[O_NSTROBE] = k_per + 1
        out.per_imp[k_per] = n_imp
        if TANGENT is not None:
            n_now = n_col + (1 if collapsed else 0)
            out.lam_run[k_per, 0] = w.lam[0] / t
            out.lam_run[k_per, 1] = w.lam[1] / t
            out.lam_run[k_per, 2] = n_now
        if ipar[I_SETTLE] > 0:
            p = settled_period(out.strobe, out.half, out.per_imp, k_per, ipar[I_SETTLE],
                               ipar[I_PMAX], par[P_SETTLE_TOL])
            if p > 0:
                out.iout[O_PERIOD] = p
                status = SETTLED
    elif j_per == n_per // 2:
        sample(EMBED4, t, y, par, out.half[k_per])
        out.iout[O_NHALF] = k_per + 1
    if record and status == RUNNING:
        j_rec += 1
        if j_rec == ipar[I_STRIDE]:
            j_rec = 0
            q = step // ipar[I_STRIDE]
            out.traj[q, 0] = t
            sample(EMBED4, t, y, par, out.traj[q, 1:])
            out.iout[O_NTRAJ] = q + 1
    return status, j_per, k_per, j_qr, j_rec, collapsed


@jit(nrt=False, inline=True)
def finish(EMBED4, TANGENT, status, t, step, n_imp, n_col_win, max_err, ipar, par, out, w):
    """The scalar outputs at the end of a run (layouts ``O_*`` and ``F_*``)."""
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    iout = out.iout
    fout = out.fout
    iout[O_STATUS] = status
    iout[O_STEPS] = step
    iout[O_IMPACTS] = n_imp
    fout[F_T] = t
    sample(EMBED4, t, w.y, par, fout[F_TH:F_S + 1])
    fout[F_MAXERR] = max_err
    if TANGENT is not None:
        for m in range(4):
            fout[F_V + m] = w.y[NS + m]
        wt = t - ipar[I_WINDOW] * ipar[I_N] * par[P_H]
        fout[F_WINTIME] = wt
        if wt > 0.0:
            fout[F_LAM1] = w.lam[2] / wt if n_col_win == 0 else -math.inf
            fout[F_LAM2] = w.lam[3] / wt if n_col_win == 0 else -math.inf
        else:
            fout[F_LAM1] = math.nan
            fout[F_LAM2] = math.nan


# What leave_rest tells the loop.
REST_END, REST_HOLD, REST_LIFT, REST_STEP = 0, 1, 2, 3


@jit(nrt=False, inline=True)
def tick(PROF):
    """The cycle counter when profiling (``PROF`` true), else 0. ``PROF`` is ``None`` in the
    single-lane loop, so that numba prunes the read before typing it (see the module's note on
    switches); the lanes pass a run-time bool (they profile only when asked)."""
    if PROF is not None and PROF:
        return cycles()
    return 0


@jit(nrt=False, inline=True)
def tock(PROF, counts, k, c0):
    """Add the cycles since ``c0`` (:func:`tick`) to ``counts[k]`` when profiling."""
    if PROF is not None and PROF:
        counts[k] += cycles() - c0


@jit(ir_inline=True)
def substep(EMBED4, TANGENT, PROF, fresh, pre, j, t, t_grid, sp, cp, side, par, out, w,
            counts):
    """The Runge–Kutta step from ``t`` to the grid point ``t_grid``: a whole grid step
    (``fresh``; with ``pre``, already taken) on the grid step's table, its forcing from the
    period's table row ``j``; or the rest of one after an event, on a table of its own length,
    the forcing rotated from its phase's sine and cosine ``sp, cp`` at ``t``. Returns
    ``(hh, sp, cp, f0, df0, f1)``: its length, the forcing's phase at its start, the forcing and
    its derivative there and the forcing at its end (for :func:`locate`)."""
    ftab = w.ftab
    if fresh:
        # a whole grid step: the forcing phase there is phi + 2 pi j / N exactly
        hh = par[P_H]
        if not pre:
            c0 = tick(PROF)
            rk_step(EMBED4, TANGENT, EMBED4 is None, 0.0, 0.0, w.y, w.K, side, par, w.ytmp,
                    w.ynew, w.tab_h, w.fr if EMBED4 is not None else ftab[j], w.jac, w.trig)
            tock(PROF, counts, np.int64(11), c0)
        sp = ftab[j, FT_SIN]
        cp = ftab[j, FT_COS]
        f0 = ftab[j, 0]
        df0 = ftab[j, FT_DF0]
        f1 = ftab[j, N_STAGES]
    else:
        c0 = tick(PROF)
        hh = t_grid - t
        step_table(par[P_OMEGA], hh, w.tab)
        rk_step(EMBED4, TANGENT, OFF_GRID, sp, cp, w.y, w.K, side, par, w.ytmp, w.ynew, w.tab,
                w.fr, w.jac, w.trig)
        tock(PROF, counts, np.int64(7), c0)
        f0 = w.fr[0]
        df0 = harmonic.slope(par[P_AW2] * par[P_OMEGA], cp)
        f1 = w.fr[N_STAGES]
    out.iout[O_RHS] += N_STAGES
    out.iout[O_SUBSTEPS] += 1
    return hh, sp, cp, f0, df0, f1


@jit(ir_inline=True)
def move_to_event(EMBED4, TANGENT, kind, lo, hi, hh, j, side, par, out, w, sp, cp, f0, df0,
                  f1):
    """The state at the event ``kind`` detected in ``(lo, hi)`` of the step of length ``hh``
    (:func:`locate`) taken into ``w.y``; an unresolvably small flight (``hi <= lo``) ends at
    rest where it started. Returns the event's time in the step."""
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    NY = NS + (4 if TANGENT is not None else 0)  # plus the tangent matrix, column-major
    y = w.y
    if hi > lo:
        tau = locate(EMBED4, TANGENT, kind, y, w.ynew, hh, lo, hi, w.K, side, par, w.ytmp,
                     w.yev, out.iout, w.tab, w.fr, w.jac, w.trig, sp, cp, f0, df0, f1,
                     w.ftab[j, FT_DF1])
    else:
        tau = 0.0
        for m in range(NY):
            w.yev[m] = y[m]
        w.yev[1] = 0.0
    for m in range(NY):
        y[m] = w.yev[m]
    return tau


@jit(ir_inline=True)
def pass_event(EMBED4, kind, t, side, par, out, w):
    """Go on from an event that does not end the step's flight: overturning in the study's
    way (the first crossing noted, then integrated on in the same field, the threshold lifted
    so that the crossing is not found again), or an uplift from rest (the block on the corner
    its forcing pushes it to). Returns the corner; the field at ``t`` is in ``w.K[0]``."""
    y = w.y
    if kind == EV_OVERTURN:
        out.fout[F_TOVER] = t
        par[P_THOVER] = math.inf
    else:
        y[0] = 0.0
        y[1] = 0.0
        side = 1 if y[2] > 0.0 else -1
    rhs(EMBED4, forcing_at(t, par), y, side, par, w.K, w.jac, w.trig)
    out.iout[O_RHS] += 1
    return side


@jit(ir_inline=True)
def rest_collapse(EMBED4, TANGENT, in_window, y, n_col, n_col_win):
    """The tangent vectors after an impact that brings the block to rest: ``(n_col,
    n_col_win)``, the collapses counted (and those in the exponents' window).

    A rest phase ends every perturbation: a nearby state reaches rest too (its Zeno cascade
    ends a little earlier or later), and the block leaves rest when the forcing alone says.
    The flow's Jacobian across it is zero, and the exponents of a stretch holding one are
    -inf (docs/theory/exponents.md): the vectors start afresh (:func:`reset_tangent`)."""
    if TANGENT is not None:
        reset_tangent(EMBED4, y)
        n_col += 1
        if in_window:
            n_col_win += 1
    return n_col, n_col_win


@jit(ir_inline=True)
def end_of_grid_step(EMBED4, TANGENT, PROF, record, t, step, side, n_imp, n_col, n_col_win,
                     in_window, ipar, par, out, w, counts, j_per, k_per, j_qr, j_rec):
    """The grid point reached without an end: the step counted, the state checked finite and
    the grid point's work done (:func:`grid_point`). Returns ``(status, step, j_per, k_per,
    j_qr, j_rec, n_col, n_col_win)``."""
    step += 1
    if not (math.isfinite(w.y[0]) and math.isfinite(w.y[1])):
        return NONFINITE, step, j_per, k_per, j_qr, j_rec, n_col, n_col_win
    c0 = tick(PROF)
    status, j_per, k_per, j_qr, j_rec, collapsed = grid_point(
        EMBED4, TANGENT, record, t, step, side, n_imp, n_col, in_window, ipar, par, out, w,
        j_per, k_per, j_qr, j_rec)
    tock(PROF, counts, np.int64(12), c0)
    if collapsed:
        n_col += 1
        if in_window:
            n_col_win += 1
    return status, step, j_per, k_per, j_qr, j_rec, n_col, n_col_win


@jit(nrt=False, inline=True)
def grid_step(EMBED4, TANGENT, record, PROF, pre, s, par, ipar, out, w, counts):
    """One grid step, from ``t`` (the grid point ``step h``, or the block still at rest) to the
    next grid point (docs/theory/integrator.md): a step of the current corner, or of rest
    (:func:`leave_rest`; ``hold``: held at rest until the grid point, where a flight that
    began at an uplift ended at rest within rounding of that instant, lest the uplift be found
    again forever); an event in it is located (:func:`move_to_event`), the state taken there
    (impact: :func:`impact`; uplift; overturning ends the run or is passed,
    :func:`pass_event`), and the step finished from the event to the grid point
    (:func:`substep`); then :func:`grid_point` (:func:`end_of_grid_step`).

    The loop's state ``s`` (a :data:`~rockjit._engine.layout.Loop`) goes in and the next comes
    back out. The one step of the single-lane loop (:func:`drive`) and of a lane taken out of
    the lanes' lockstep (:mod:`rockjit._engine.lanes`): with ``pre`` the grid step's first
    Runge–Kutta step is already in ``K``, ``w.ynew``, ``w.jac`` and ``w.trig``. With ``PROF``,
    ``counts[6:13]`` receive the cycles spent in rest phases, in the steps after an event, in
    locating, in impacts, in detection, in the first step and at the grid point (the lanes'
    accounting, a run-time bool; the single-lane loop passes ``PROF = None``: :func:`tick`).
    """
    t, side, n_imp, step, j_per, k_per, j_qr, j_rec = (s.t, s.side, s.n_imp, s.step, s.j_per,
                                                       s.k_per, s.j_qr, s.j_rec)
    n_col, n_col_win, t_lift, max_err = s.n_col, s.n_col_win, s.t_lift, s.max_err
    y = w.y
    status = RUNNING
    j = j_per
    t_grid = (step + 1) * par[P_H]
    in_window = step >= ipar[I_WINDOW] * ipar[I_N]
    fresh = True  # no event yet in this grid step
    jn = j + 1 if j + 1 < ipar[I_N] else 0  # the grid point's row of the forcing table
    sp, cp = 0.0, 0.0  # sine and cosine of the forcing phase at t, off the grid (phase_before_grid)
    hold = step < 0  # False, typed bool rather than the literal (one compilation of leave_rest)
    while True:
        if side == 0:
            c0 = tick(PROF)
            action, t, side = leave_rest(EMBED4, t, t_grid, hold, y, side, par, w, out.iout)
            tock(PROF, counts, np.int64(6), c0)
            if action == REST_END:
                status = REST
                break
            if action == REST_HOLD:
                break
            if action == REST_LIFT:
                t_lift = t
                fresh = EMBED4 is not None and fresh
                sp, cp = phase_before_grid(EMBED4, w.ftab, jn, par[P_OMEGA] * (t_grid - t))
                continue
        hh, sp, cp, f0, df0, f1 = substep(EMBED4, TANGENT, PROF, fresh, pre, j, t, t_grid, sp,
                                          cp, side, par, out, w, counts)
        pre = False
        c0 = tick(PROF)
        kind, lo, hi = detect(y, w.ynew, hh, w.K, side, par)
        tock(PROF, counts, np.int64(10), c0)
        if kind == EV_NONE or (hold and kind == EV_UPLIFT):
            max_err = accept(EMBED4, TANGENT, side, hh, max_err, w)
            t = t_grid
            break
        c0 = tick(PROF)
        tau = move_to_event(EMBED4, TANGENT, kind, lo, hi, hh, j, side, par, out, w, sp, cp, f0,
                            df0, f1)
        tock(PROF, counts, np.int64(8), c0)
        t = t + tau
        fresh = False
        # the forcing phase at the event, for the rest of the step (and its forcing)
        sp, cp = phase_before_grid(EMBED4, w.ftab, jn, par[P_OMEGA] * (t_grid - t))
        if kind == EV_OVERTURN and ipar[I_CONTINUE] == 0:
            status = OVERTURNED
            break
        if kind == EV_OVERTURN or kind == EV_UPLIFT:
            if kind == EV_UPLIFT:
                t_lift = t
            side = pass_event(EMBED4, kind, t, side, par, out, w)
            continue
        c0 = tick(PROF)
        side, n_imp, rests, held = impact(EMBED4, TANGENT, t, sp, t_lift, side, n_imp,
                                          in_window, par, out, w)
        tock(PROF, counts, np.int64(9), c0)
        if rests:
            hold = hold or held
            n_col, n_col_win = rest_collapse(EMBED4, TANGENT, in_window, y, n_col, n_col_win)
        if n_imp >= ipar[I_MAXIMP]:
            status = MAX_IMPACTS
            break
    if status == RUNNING:
        status, step, j_per, k_per, j_qr, j_rec, n_col, n_col_win = end_of_grid_step(
            EMBED4, TANGENT, PROF, record, t, step, side, n_imp, n_col, n_col_win, in_window,
            ipar, par, out, w, counts, j_per, k_per, j_qr, j_rec)
    return Loop(status, t, side, n_imp, step, j_per, k_per, j_qr, j_rec, n_col, n_col_win,
                t_lift, max_err)


@jit(nrt=False)
def drive(EMBED4, TANGENT, record, status, side0, par, ipar, out, w):
    """The integration from its start (:func:`start`: the tables made, status ``status`` on
    corner ``side0``), with the parameters and their derived constants (``N_PARW``) and the
    :data:`Work` arrays ``w``: grid step by grid step (:func:`grid_step`) to the end, then
    :func:`finish`; returns the status code. The one driver loop of a run, on the CPU
    (:func:`_run`) and on the GPU (:mod:`rockjit._engine.gpu`); the step's pieces are inlined
    into it."""
    n_per = ipar[I_N]
    total = n_per * ipar[I_PERIODS]
    # the counters start as int64, not as the literal 0: numba would type (and compile) every
    # piece they are passed to once more for the literal
    zero = np.int64(0)
    n_col = out.iout[O_NCOL]  # collapses of the tangent vectors (start at rest; see below)
    s = Loop(np.int64(status), 0.0, np.int64(side0), zero, zero, zero, zero, zero, zero, n_col,
             n_col if ipar[I_WINDOW] == 0 else zero, -math.inf, 0.0)
    while s.step < total and s.status == RUNNING:
        s = grid_step(EMBED4, TANGENT, record, None, False, s, par, ipar, out, w, out.iout)
    status = s.status
    if status == RUNNING:
        status = DONE
    out.iout[O_NCOL] = s.n_col
    finish(EMBED4, TANGENT, status, s.t, s.step, s.n_imp, s.n_col_win, s.max_err, ipar, par,
           out, w)
    return status


@functools.lru_cache(maxsize=None)
def _build(EMBED4, TANGENT):
    # The closure only forwards its flags: numba types them as literals, so _run and its helpers
    # are specialised (and cached, being module-level) once per combination of switches.
    # Recording is decided at run time (see _run).
    @jit
    def run(y0, side0, par, ipar, out):
        return _run(EMBED4, TANGENT, y0, side0, par, ipar, out)

    return run
