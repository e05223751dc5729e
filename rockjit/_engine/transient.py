"""The compiled integrator for transient excitations: grids of runs under pulses and records.

Each cell is one block, at rest at ``t = 0``, under one pulse or record; the cells of a grid
are independent and run in a ``prange`` loop (:func:`run_cells`), each written to its own
index, so the results do not depend on the number of threads. A cell follows the phases of the
scipy reference path (:mod:`rockjit.ground.reference`, the specification):

- **rest**: the block leaves rest at the first instant after which ``|f| > cot(thc)``, on the
  corner ``sign f``: the excitation's windows come from its plug
  (:func:`rockjit.plugs.plug_window`), and the instant is nudged by the same units in the last
  place as on the reference path until :func:`rockjit.model.accel` on that corner is outward;
- **flight**: fixed steps of the Dormand–Prince 5(4) tableau, the stage chain the harmonic
  engine renders too (:func:`rockjit._engine.step.dp_step`), on the grid the excitation's plug
  gives, which puts
  every kink of the forcing on a step boundary (a pulse's duration cut into equal steps, a
  record's sample step into ``k`` equal steps), then free rocking after the excitation in
  steps of its own length. A step that crosses ``theta = 0`` (an impact),
  ``|theta| = theta_over`` (overturning) or ``theta' = 0`` (a turning point: a crest gives
  ``max |theta|`` and, after the excitation, may decide the run; a trough below ``theta = 0``
  is a dip through an impact and back) is cut there (:mod:`rockjit._engine.events`): the
  instant is the root of the event function of a genuine step of variable length from the
  step's start, found by Newton's iteration kept inside its bracket by bisection
  (:func:`rockjit._engine.events.locate_transient`), so the event's state has the step's own
  order of accuracy;
- **impact**: :func:`rockjit.model.jump` on the other corner, or rest below ``rest_speed``;
- **decided** (``decide``): after the excitation, the run stops at the first grid point, crest
  or impact from which free rocking can neither overturn nor swing wider than the largest
  ``|theta|`` so far (:func:`rockjit.model.free_rocking_decided`, the reference path's rule).

The forcing may jump where the excitation ends (the one-cosine pulse ends on ``a_p``): the last
step of the excitation sees its value there (its stages never pass the grid instant that ends
it), and free rocking starts from the still base, its first stage included.

Every equation of the block comes from :mod:`rockjit.model` (here :func:`~rockjit.model.jump`,
:func:`~rockjit.model.accel`, :func:`~rockjit.model.free_rocking_decided`; in the step,
:func:`~rockjit.model.corner`, :func:`~rockjit.model.accel_pq`), and every
excitation from its plug (:mod:`rockjit.plugs`: the pulses, records, sums of harmonics), the
step from :mod:`rockjit._engine.step` and the events' location from
:mod:`rockjit._engine.events`: this module writes none of them; it drives them. The forcing
of a cell is described by a row of ``xpar`` (columns ``X_*``): its plug's code, its amplitude,
the excitation's end, its grid, and where its coefficients lie in one flat array.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from .._jit import jit
from ..laws.impact import restitution_at
from ..model import accel, free_rocking_decided, jump
from ..plugs import plug_window
from .events import crest_in, impact_in, reach_in
from .step import dp_step, free_acc, plug_acc, plug_forcing

# ---- codes --------------------------------------------------------------------------------------
#: columns of a cell's forcing row ``xpar``: its plug's code, its amplitude (the plug's ``a``),
#: the end of the excitation, the step between the grid's kinks (0: none), the offset and
#: number of its coefficients in the flat array ``rec``, the grid's steps (over the excitation,
#: or between kinks)
X_CODE, X_AMP, X_END, X_DT, X_OFF, X_N, X_STEPS = range(7)
N_X = 7
#: columns of a block's row ``bpar``: thc, xi, e, cot (uplift threshold), th_top (the tipping
#: angle, or theta_over below it), alpha_s, the law's kind and shape at an impact
#: (rockjit.laws.impact.restitution_at)
B_THC, B_XI, B_E, B_COT, B_THTOP, B_ALPHA, B_LAW, B_LAW_SHAPE = range(8)
N_B = 8
#: the run's settings ``spar``: theta_over, rest_speed, the step length of free rocking
S_THOVER, S_REST, S_HFREE = range(3)
N_S = 3
#: statuses, in the order of rockjit.ground.response.STATUSES
ST_OVERTURNED, ST_REST, ST_DECIDED, ST_TIME_LIMIT, ST_MAX_IMPACTS, ST_NONFINITE = range(6)
#: outcomes, in the order of rockjit.ground.response.OUTCOMES
OC_SAFE, OC_OVER_IMPACT, OC_OVER_NO_IMPACT, OC_UNRESOLVED = range(4)

_TINY = float(np.finfo(float).tiny)


# ---- the forcing --------------------------------------------------------------------------------

@jit(nrt=False, inline=True)
def forcing_of(x):
    """A cell's forcing row ``x`` as the tuple the step reads, taken once per cell:
    ``(end, plug code, amplitude, offset and number of its coefficients)``."""
    return x[X_END], int(x[X_CODE]), x[X_AMP], int(x[X_OFF]), int(x[X_N])


# ---- when the block leaves rest -----------------------------------------------------------------

@jit(nrt=False)
def _ulp(x):
    """``math.ulp(x)`` for a finite ``x >= 1``."""
    _, e = math.frexp(x)
    return math.ldexp(1.0, e - 53)


@jit(nrt=False)
def next_uplift(t, fx, rec, thc, xi, thr):
    """``(t_up, side)``: the first instant ``>= t`` at which the block at rest accelerates away
    from it, ``side`` 0 when there is none (the reference path's ``next_uplift``): through the
    windows where ``|f| > thr`` (:func:`rockjit.plugs.plug_window`), in order."""
    end, code, a, off, n = fx
    tq = t
    while True:
        t0, t1, sg = plug_window(code, tq, end, a, rec, off, n, thr)
        if sg == 0.0:
            return 0.0, 0
        side = int(sg)
        base = max(t, t0)
        tt = base
        step = 0.0
        while tt <= t1:
            if side * accel(side * _TINY, 0.0, plug_forcing(tt, fx, rec), side, thc, xi) > 0.0:
                return tt, side
            step = max(2.0 * step, _ulp(max(tt, 1.0)))
            tt = base + step
        tq = t1


# ---- one cell -----------------------------------------------------------------------------------

@jit(nrt=False, inline=True)
def grid_next(t, end, h_exc, nsub, dt, h_free, t_lim):
    """The first grid instant after ``t``: during the excitation, multiples of ``h_exc`` up to
    ``end`` or, for a grid with kinks (``nsub > 0``: a record), ``nsub`` equal steps between
    consecutive multiples of ``dt``, the kinks exact; after the excitation, ``end`` plus
    multiples of ``h_free``; never beyond ``t_lim``."""
    if t < end:
        j = int(t / h_exc) + 1
        if nsub > 0:
            tn = (j // nsub) * dt + (j % nsub) * h_exc
            while tn <= t:
                j += 1
                tn = (j // nsub) * dt + (j % nsub) * h_exc
        else:
            tn = j * h_exc
            while tn <= t:
                j += 1
                tn = j * h_exc
        if tn > end or end - tn < 1e-9 * h_exc:
            tn = end
    else:
        j = int((t - end) / h_free) + 1
        tn = end + j * h_free
        while tn <= t:
            j += 1
            tn = end + j * h_free
    return min(tn, t_lim)


#: a cell's float outputs ``out_f``: max|theta| / alpha_s, t_overturn, the time it stopped,
#: the first uplift, theta and theta' there, max|theta|
TF_MAXROT, TF_TOVER, TF_T, TF_TUP, TF_TH, TF_DTH, TF_MAXTH = range(7)
N_TF = 7
#: its integer outputs ``out_i``: outcome, impacts, status, rest phases entered after an impact,
#: trajectory points (recorded up to the buffer's length), steps taken (each six evaluations
#: of the right-hand side), the events' included
TI_OUTCOME, TI_IMPACTS, TI_STATUS, TI_REST, TI_TRAJ, TI_STEPS = range(6)
N_TI = 6


@jit(nrt=False, inline=True)
def _keep(traj, n, t, th, v):
    """Row ``n`` of the trajectory ``(t, theta, theta')``, if the buffer holds it; ``n + 1``."""
    if n < traj.shape[0]:
        traj[n, 0] = t
        traj[n, 1] = th
        traj[n, 2] = v
    return n + 1


@jit(ir_inline=True)
def _start(out_f, out_i):
    """A cell's outputs before its run: the impacts and rests at zero, no overturning or
    uplift yet."""
    out_i[TI_IMPACTS] = 0
    out_i[TI_REST] = 0
    out_f[TF_TOVER] = math.nan
    out_f[TF_TUP] = math.nan


@jit(ir_inline=True)
def _grid(x, s):
    """The step grid of the forcing row ``x`` (``grid_next``'s ``h_exc, nsub, dt, h_free``):
    the excitation in ``X_STEPS`` equal steps, or ``X_STEPS`` steps between its kinks
    (multiples of ``X_DT``), free rocking in steps of ``S_HFREE``."""
    dt = x[X_DT]
    if dt > 0.0:
        nsub = int(x[X_STEPS])
        return dt / nsub, nsub, dt, s[S_HFREE]
    return x[X_END] / x[X_STEPS], 0, dt, s[S_HFREE]


@jit(ir_inline=True)
def _leave_rest(t, fx, rec, thc, xi, thr, t_lim, traj, n_tr, out_f):
    """The block at rest at ``t``: ``(t, side, trajectory rows, -1)`` where it lifts off, the
    corner ``side``; or ``side`` 0 and the run's status (rest for good, or the time limit
    first)."""
    t_up, up = next_uplift(t, fx, rec, thc, xi, thr)
    if up == 0:
        return t, 0, n_tr, ST_REST
    if t_up >= t_lim:
        return t_lim, 0, _keep(traj, n_tr, t_lim, 0.0, 0.0), ST_TIME_LIMIT
    if t_up > t:
        n_tr = _keep(traj, n_tr, t_up, 0.0, 0.0)
    if math.isnan(out_f[TF_TUP]):
        out_f[TF_TUP] = t_up
    return t_up, up, n_tr, -1


@jit(ir_inline=True)
def _land(t, v2, side, b, rest_speed, imp, out_i):
    """The impact at ``t`` with ``theta'(-) = v2`` on corner ``side``: the jump of the
    block's law (:func:`rockjit.model.jump`), kept in ``imp`` if it holds it; ``(theta,
    theta', side)`` after it on the other corner, or at rest below ``rest_speed``."""
    dth_p = jump(v2, restitution_at(int(b[B_LAW]), abs(v2), b[B_E], b[B_LAW_SHAPE])[0])
    n_imp = out_i[TI_IMPACTS]
    if n_imp < imp.shape[0]:
        imp[n_imp, 0] = t
        imp[n_imp, 1] = v2
        imp[n_imp, 2] = dth_p
    out_i[TI_IMPACTS] = n_imp + 1
    if abs(dth_p) < rest_speed or dth_p == 0.0:
        out_i[TI_REST] += 1
        return 0.0, 0.0, 0
    return -side * _TINY, dth_p, -side


@jit(ir_inline=True)
def _finish(status, t, th, v, max_th, n_step, n_tr, end, alpha, out_f, out_i):
    """A finished cell's status and outcome, its last state, ``max |theta|``, the steps it
    took and its trajectory's rows."""
    out_f[TF_MAXTH] = max_th
    out_i[TI_STEPS] = n_step
    out_i[TI_TRAJ] = n_tr
    out_i[TI_STATUS] = status
    if status == ST_OVERTURNED:
        outcome = OC_OVER_IMPACT if out_i[TI_IMPACTS] > 0 else OC_OVER_NO_IMPACT
    elif status == ST_REST or status == ST_DECIDED or (status == ST_TIME_LIMIT and t >= end):
        outcome = OC_SAFE
    else:
        outcome = OC_UNRESOLVED
    out_i[TI_OUTCOME] = outcome
    out_f[TF_MAXROT] = out_f[TF_MAXTH] / alpha
    out_f[TF_T] = t
    out_f[TF_TH] = th
    out_f[TF_DTH] = v


@jit(nrt=False)
def run_cell(x, rec, b, s, t_lim, max_impacts, decide, th0, v0, side0, imp, traj, out_f, out_i):
    """One run from ``(th0, v0)`` on corner ``side0`` (0: at rest): writes ``out_f`` and
    ``out_i`` (``TF_*``, ``TI_*``; they hold the run's impact and rest counts as it goes).
    ``imp`` (rows ``t, theta'-, theta'+``) and ``traj`` (rows ``t, theta, theta'`` at the grid
    points and the events) keep what their lengths hold: buffers of no rows for a grid, which
    needs neither."""
    thc, xi, thr, th_top = b[B_THC], b[B_XI], b[B_COT], b[B_THTOP]
    sthc, cthc, thover = math.sin(thc), math.cos(thc), s[S_THOVER]
    fx = forcing_of(x)
    end = x[X_END]
    h_exc, nsub, dt, h_free = _grid(x, s)
    _start(out_f, out_i)
    t, th, v, side, max_th, n_step, status = 0.0, th0, v0, side0, abs(th0), 0, -1
    a = plug_acc(th, v, t, side, sthc, cthc, xi, fx, rec) if side != 0 else 0.0
    n_tr = _keep(traj, 0, t, th, v)
    while status < 0:
        if t >= t_lim:
            status = ST_TIME_LIMIT
            break
        if side == 0:  # ---- at rest ------------------------------------------------------------
            t, side, n_tr, status = _leave_rest(t, fx, rec, thc, xi, thr, t_lim, traj, n_tr,
                                                out_f)
            if side == 0:
                break
            th, v = side * _TINY, 0.0
            a = plug_acc(th, v, t, side, sthc, cthc, xi, fx, rec)
            continue
        if decide and t >= end and free_rocking_decided(th, v, max_th, thc, th_top):
            status = ST_DECIDED
            break
        # ---- one step on corner `side` --------------------------------------------------------
        tn = grid_next(t, end, h_exc, nsub, dt, h_free, t_lim)
        hh = tn - t
        th1, v1, a1 = dp_step(t, th, v, a, hh, tn, side, sthc, cthc, xi, fx, rec)
        n_step += 1
        if not (math.isfinite(th1) and math.isfinite(v1) and math.isfinite(a1)):
            status = ST_NONFINITE
            break
        crest, lo, th_c, vc, ns = crest_in(t, th, v, a, hh, tn, v1, side, sthc, cthc, xi, fx, rec)
        n_step += ns
        if crest:
            max_th = max(max_th, abs(th_c))
            if decide and t + lo >= end and free_rocking_decided(th_c, 0.0, max_th, thc,
                                                                 th_top):
                t, th, v = t + lo, th_c, vc
                n_tr = _keep(traj, n_tr, t, th, v)
                status = ST_DECIDED
                break
        if side * th1 >= thover:  # overturning
            tau, th, v, ns = reach_in(0, thover, side * th - thover, t, th, v, a, 0.0, hh, tn,
                                      side, sthc, cthc, xi, fx, rec)
            n_step += ns
            t = out_f[TF_TOVER] = t + tau
            n_tr = _keep(traj, n_tr, t, th, v)
            max_th = max(max_th, thover)
            status = ST_OVERTURNED
            break
        impact_at, ns = impact_in(crest, t, th, v, a, hh, tn, th1, v1, side, sthc, cthc, xi,
                                  fx, rec)
        n_step += ns
        if impact_at < 0.0:
            if t < end <= tn:  # the excitation ends here: free rocking from f = 0 on
                a1 = free_acc(th1, v1, side, sthc, cthc, xi)
            t, th, v, a = tn, th1, v1, a1
            n_tr = _keep(traj, n_tr, t, th, v)
            max_th = max(max_th, abs(th))
            continue
        # ---- impact --------------------------------------------------------------------------
        tau, th2, v2, ns = reach_in(0, 0.0, side * th if lo == 0.0 else side * th_c, t, th, v,
                                    a, lo, impact_at, tn, side, sthc, cthc, xi, fx, rec)
        n_step += ns
        t = t + tau
        n_tr = _keep(traj, n_tr, t, 0.0, v2)
        th, v, side = _land(t, v2, side, b, s[S_REST], imp, out_i)
        if side != 0:
            a = plug_acc(th, v, t, side, sthc, cthc, xi, fx, rec)
        if out_i[TI_IMPACTS] >= max_impacts:
            status = ST_MAX_IMPACTS
            break
    _finish(status, t, th, v, max_th, n_step, n_tr, end, b[B_ALPHA], out_f, out_i)


@jit(parallel=True)
def run_cells(xpar, rec, bpar, block_of, spar, t_lim, max_impacts, decide, stride, out_f,
              out_i):
    """Every cell ``i`` (forcing row ``xpar[i]``, block row ``bpar[block_of[i]]``, time limit
    ``t_lim[i]``) in parallel, each alone, into row ``i`` of ``out_f`` and ``out_i``
    (:func:`run_cell`). The loop visits the cells with the given ``stride`` (the threads), so
    that each thread's contiguous share of the loop holds every ``stride``-th cell: neighbouring
    cells (a spectrum's long pulses, say) cost alike and are spread over the threads."""
    n = xpar.shape[0]
    per = (n + stride - 1) // stride
    none = np.empty((0, 3))  # no impacts or trajectory kept: read only, shared
    for k in prange(per * stride):
        i = (k % per) * stride + k // per
        if i >= n:
            continue
        run_cell(xpar[i], rec, bpar[block_of[i]], spar, t_lim[i], max_impacts, decide, 0.0,
                 0.0, 0, none, none, out_f[i], out_i[i])
