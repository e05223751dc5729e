"""The compiled integrator for transient excitations: grids of runs under pulses and records.

Each cell is one block, at rest at ``t = 0``, under one pulse or record; the cells of a grid
are independent and run in a ``prange`` loop (:func:`run_cells`), each written to its own
index, so the results do not depend on the number of threads. A cell follows the phases of the
scipy reference path (:mod:`rockjit.ground.reference`, the specification):

- **rest**: the block leaves rest at the first instant after which ``|f| > cot(thc)``, on the
  corner ``sign f``: the excitation's windows are found here as the reference path finds them
  (in closed form for the sine and cosine pulses, by bisection to rounding on the Ricker
  wavelet's lobes, on their linear pieces for a record), and the instant nudged by the same
  units in the last place until :func:`rockjit.model.accel` on that corner is outward;
- **flight**: fixed steps of the Dormand–Prince 5(4) tableau of the harmonic engine
  (:mod:`rockjit._engine.integrate`), on a grid that puts every kink of the forcing on a step
  boundary: a pulse's duration is cut into equal steps, a record's sample step into ``k``
  equal steps, free rocking after the excitation into steps of its own length. A step that
  crosses ``theta = 0`` (an impact), ``|theta| = theta_over`` (overturning) or ``theta' = 0``
  (a turning point: a crest gives ``max |theta|`` and, after the excitation, may decide the
  run; a trough below ``theta = 0`` is a dip through an impact and back) is cut there: the
  instant is the root of the event function of a genuine step of variable length from the
  step's start, found by Newton's iteration kept inside its bracket by bisection, so the
  event's state has the step's own order of accuracy;
- **impact**: :func:`rockjit.model.jump` on the other corner, or rest below ``rest_speed``;
- **decided** (``decide``): after the excitation, the run stops at the first grid point, crest
  or impact from which free rocking can neither overturn nor swing wider than the largest
  ``|theta|`` so far (:func:`rockjit.model.free_rocking_decided`, the reference path's rule).

The forcing may jump where the excitation ends (the one-cosine pulse ends on ``a_p``): the last
step of the excitation sees its value there (its stages never pass the grid instant that ends
it), and free rocking starts from the still base, its first stage included.

Every equation of the block comes from :mod:`rockjit.model` (:func:`~rockjit.model.corner`,
:func:`~rockjit.model.accel_pq`, :func:`~rockjit.model.sincos`, :func:`~rockjit.model.jump`,
:func:`~rockjit.model.accel`, :func:`~rockjit.model.free_rocking_decided`); this module writes
none. The excitations are the one thing it writes again: :func:`forcing` and the uplift
windows are the compiled twins of ``Pulse.scalar``/``Pulse.windows`` and
``Record.scalar``/``Record.windows``, held to them by the tests that compare every cell with
the scipy path, which evaluates those.

The forcing of a cell is described by a row of ``xpar`` (columns ``X_*``): the kind (0, 1, 2:
the pulses of :data:`rockjit.ground.pulses.KINDS`; 3: a record; from
:data:`rockjit.plugs.FIRST_KIND` on, an excitation plug), its amplitude in ``g`` (a gain, for a
plug), the pulse's ``omega_p``, the end, the Ricker wavelet's delay, the record's model time
step, the offset and length of its samples (a plug's numbers) in one flat array, and the steps
of the grid (per pulse or plug, or per record sample). A plug's value and windows are its own
compiled functions (:func:`rockjit.plugs.plug_value`, :func:`rockjit.plugs.plug_window`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from .._jit import jit
from ..laws.impact import restitution_at
from ..model import accel, accel_pq, corner, free_rocking_decided, jump, sincos
from ..plugs import FIRST_KIND, plug_value, plug_window
from .stages import chain, compile_step, node

# ---- codes --------------------------------------------------------------------------------------
K_SINE, K_COSINE, K_RICKER, K_RECORD = 0, 1, 2, 3
#: columns of a cell's forcing row ``xpar``
X_KIND, X_AMP, X_OMEGA, X_END, X_DELAY, X_DT, X_OFF, X_N, X_STEPS = range(9)
N_X = 9
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
_EPS = float(np.finfo(float).eps)
ROOT_ITERS = 60


# ---- the forcing --------------------------------------------------------------------------------

@jit(nrt=False, inline=True)
def forcing(t, x, rec):
    """The base acceleration (``g``) of the forcing row ``x`` at model time ``t``: the formulas
    of ``Pulse.scalar`` and ``Record.scalar``, zero outside ``[0, end]``."""
    end = x[X_END]
    if not (0.0 <= t <= end):
        return 0.0
    kind = int(x[X_KIND])
    a = x[X_AMP]
    if kind == K_SINE:
        return a * math.sin(x[X_OMEGA] * t)
    if kind == K_COSINE:
        return a * math.cos(x[X_OMEGA] * t)
    if kind == K_RICKER:
        u = 0.5 * x[X_OMEGA] * (t - x[X_DELAY])
        u2 = u * u
        return a * (1.0 - 2.0 * u2) * math.exp(-u2)
    if kind >= FIRST_KIND:
        return a * plug_value(kind, t, rec, int(x[X_OFF]), int(x[X_N]))
    off = int(x[X_OFF])
    last = int(x[X_N]) - 1
    q = t / x[X_DT]
    k = int(q)
    if k >= last:
        return a * rec[off + last]
    w = q - k
    y0 = a * rec[off + k]
    y1 = a * rec[off + k + 1]
    return y0 + w * (y1 - y0)


@jit(nrt=False, inline=True)
def acc(th, v, t, side, sthc, cthc, xi, x, rec):
    """``theta''`` on corner ``side`` at ``(t, th, v)``: :func:`rockjit.model.corner` and
    :func:`rockjit.model.accel_pq` (what :func:`rockjit.model.accel` computes, with the
    block's ``sin(thc), cos(thc)`` taken once)."""
    P, Q = corner(forcing(t, x, rec), side, sthc, cthc)
    s, c = sincos(th)
    return accel_pq(P, Q, s, c, v, xi)


@jit(nrt=False, inline=True)
def acc_free(th, v, side, sthc, cthc, xi):
    """``theta''`` on corner ``side`` with the base still (after the excitation)."""
    P, Q = corner(0.0, side, sthc, cthc)
    s, c = sincos(th)
    return accel_pq(P, Q, s, c, v, xi)


def _stage(i):
    """Stage ``i``'s ``theta''``, its instant kept at or below ``cap``."""
    c = node(i)
    at = "t + hh" if c == "1.0" else f"t + {c} * hh"
    return f"k{i} = acc(x{i}, v{i}, min({at}, cap), side, sthc, cthc, xi, x, rec)"


dp_step = compile_step(
    "dp_step", "t, x0, v0, k0, hh, cap, side, sthc, cthc, xi, x, rec",
    chain(_stage, arith="plain", form="first", h="hh") + ["return x6, v6, k6"],
    globals(), jit(nrt=False, inline=True), doc="""One Dormand–Prince step of length ``hh``
    from ``(t, theta, theta')`` (``k0``: ``theta''`` there): ``(theta, theta', theta'')`` at
    ``t + hh``, the stage chain of :mod:`rockjit._engine.stages` in its first-order form with
    literal coefficients. The stages' instants are kept at or below ``cap``, the grid instant
    that ends the step: a step that ends on the excitation's end sees the forcing's value there
    even where ``t + hh`` rounds beyond it (the one-cosine pulse ends on ``a_p``).""")


@jit(nrt=False)
def locate(kind, target, t, th, v, a0, lo, hi, glo, cap, side, sthc, cthc, xi, x, rec):
    """The root in ``(lo, hi)`` of an event function along genuine steps from ``(t, th, v)``:
    ``kind`` 0, ``side * theta - target`` (slope ``side * theta'``); ``kind`` 1,
    ``side * theta'`` (slope ``side * theta''``). ``glo`` has its sign just after ``lo``, and
    its value at ``hi`` has the other sign. Newton's iteration, bisection where it would leave the
    bracket. Returns ``(tau, theta, theta', theta'', steps taken)`` at the root."""
    tol = 4.0 * _EPS * max(1.0, abs(t) + hi)
    z = lo + 0.5 * (hi - lo)
    steps = 1
    for _ in range(ROOT_ITERS):
        steps += 1
        th1, v1, a1 = dp_step(t, th, v, a0, z, cap, side, sthc, cthc, xi, x, rec)
        if kind == 0:
            g, dg = side * th1 - target, side * v1
        else:
            g, dg = side * v1, side * a1
        if g == 0.0:
            return z, th1, v1, a1, steps
        if (g > 0.0) == (glo > 0.0):
            lo, glo = z, g
        else:
            hi = z
        zn = z - g / dg if dg != 0.0 else lo + 0.5 * (hi - lo)
        if not (lo < zn < hi):
            zn = lo + 0.5 * (hi - lo)
        if abs(zn - z) <= tol or hi - lo <= tol:
            z = zn
            break
        z = zn
    th1, v1, a1 = dp_step(t, th, v, a0, z, cap, side, sthc, cthc, xi, x, rec)
    return z, th1, v1, a1, steps


# ---- when the block leaves rest -----------------------------------------------------------------

@jit(nrt=False)
def _ulp(x):
    """``math.ulp(x)`` for a finite ``x >= 1``."""
    _, e = math.frexp(x)
    return math.ldexp(1.0, e - 53)


@jit(nrt=False)
def _ricker_root(r, lo, hi, lobe):
    """The ``u`` in ``[lo, hi]`` where the Ricker shape ``g(u) = (1 - 2u^2) exp(-u^2)`` meets
    ``r`` (``lobe`` 1: the main lobe, ``g = r``; -1: a side lobe, ``-g = r``), by bisection to
    adjacent floats."""
    glo = lobe * (1.0 - 2.0 * lo * lo) * math.exp(-lo * lo) - r
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        g = lobe * (1.0 - 2.0 * mid * mid) * math.exp(-mid * mid) - r
        if g == 0.0:
            return mid
        if (g > 0.0) == (glo > 0.0):
            lo, glo = mid, g
        else:
            hi = mid
    return 0.5 * (lo + hi)


@jit(nrt=False)
def pulse_windows(x, thr, win):
    """The rows ``(t_start, t_end, sign f)`` where a pulse's ``|f| > thr``, in order, written
    to ``win`` (3 x 3); returns their number (``Pulse.windows``)."""
    a, w = x[X_AMP], x[X_OMEGA]
    if not a > thr:
        return 0
    r = thr / a
    kind = int(x[X_KIND])
    if kind == K_SINE:
        s = math.asin(r)
        win[0, 0], win[0, 1], win[0, 2] = s / w, (math.pi - s) / w, 1.0
        win[1, 0], win[1, 1], win[1, 2] = (math.pi + s) / w, (2.0 * math.pi - s) / w, -1.0
        return 2
    if kind == K_COSINE:
        c = math.acos(r)
        win[0, 0], win[0, 1], win[0, 2] = 0.0, c / w, 1.0
        win[1, 0], win[1, 1], win[1, 2] = (math.pi - c) / w, (math.pi + c) / w, -1.0
        win[2, 0], win[2, 1], win[2, 2] = (2.0 * math.pi - c) / w, 2.0 * math.pi / w, 1.0
        return 3
    t0 = x[X_DELAY]
    um = _ricker_root(r, 0.0, math.sqrt(0.5), 1.0)
    if r < 2.0 * math.exp(-1.5):  # deeper than the side lobes
        ui = _ricker_root(r, math.sqrt(0.5), math.sqrt(1.5), -1.0)
        uo = _ricker_root(r, math.sqrt(1.5), 10.0, -1.0)
        win[0, 0], win[0, 1], win[0, 2] = t0 + 2.0 * -uo / w, t0 + 2.0 * -ui / w, -1.0
        win[1, 0], win[1, 1], win[1, 2] = t0 + 2.0 * -um / w, t0 + 2.0 * um / w, 1.0
        win[2, 0], win[2, 1], win[2, 2] = t0 + 2.0 * ui / w, t0 + 2.0 * uo / w, -1.0
        return 3
    win[0, 0], win[0, 1], win[0, 2] = t0 + 2.0 * -um / w, t0 + 2.0 * um / w, 1.0
    return 1


@jit(nrt=False)
def _excess(x, rec, j, sg, thr):
    return sg * (x[X_AMP] * rec[int(x[X_OFF]) + j]) - thr


@jit(nrt=False)
def record_window(tq, x, rec, thr):
    """The first window ``(t_start, t_end, sign f)`` of a record with ``t_end > tq``
    (``Record.windows``: runs of samples with ``|f| > thr``, their ends on the linear pieces);
    ``sign`` 0 when there is none."""
    n = int(x[X_N])
    dt = x[X_DT]
    j = max(0, int(tq / dt) - 1)
    while j < n:
        sg = 0.0
        if _excess(x, rec, j, 1.0, thr) > 0.0:
            sg = 1.0
        elif _excess(x, rec, j, -1.0, thr) > 0.0:
            sg = -1.0
        if sg == 0.0:
            j += 1
            continue
        i = j
        while i > 0 and _excess(x, rec, i - 1, sg, thr) > 0.0:
            i -= 1
        if i == 0:
            start = 0.0
        else:
            s0, s1 = _excess(x, rec, i - 1, sg, thr), _excess(x, rec, i, sg, thr)
            start = (i - 1) * dt + (-s0) / (s1 - s0) * dt
        m = j
        while m + 1 < n and _excess(x, rec, m + 1, sg, thr) > 0.0:
            m += 1
        if m == n - 1:
            stop = (n - 1) * dt
        else:
            s0, s1 = _excess(x, rec, m, sg, thr), _excess(x, rec, m + 1, sg, thr)
            stop = m * dt + s0 / (s0 - s1) * dt
        if stop > tq:
            return start, stop, sg
        j = m + 1
    return 0.0, 0.0, 0.0


@jit(nrt=False)
def next_uplift(t, x, rec, win, nwin, thc, xi, thr):
    """``(t_up, side)``: the first instant ``>= t`` at which the block at rest accelerates away
    from it, ``side`` 0 when there is none (the reference path's ``next_uplift``)."""
    kind = int(x[X_KIND])
    k = 0
    tq = t
    while True:
        if kind == K_RECORD:
            t0, t1, sg = record_window(tq, x, rec, thr)
            if sg == 0.0:
                return 0.0, 0
        elif kind >= FIRST_KIND:
            a = x[X_AMP]
            if not a > 0.0:
                return 0.0, 0
            t0, t1, sg = plug_window(kind, tq, x[X_END], rec, int(x[X_OFF]), int(x[X_N]),
                                     thr / a)
            if sg == 0.0:
                return 0.0, 0
        else:
            while k < nwin and not win[k, 1] > t:
                k += 1
            if k >= nwin:
                return 0.0, 0
            t0, t1, sg = win[k, 0], win[k, 1], win[k, 2]
        side = int(sg)
        base = max(t, t0)
        tt = base
        step = 0.0
        while tt <= t1:
            if side * accel(side * _TINY, 0.0, forcing(tt, x, rec), side, thc, xi) > 0.0:
                return tt, side
            step = max(2.0 * step, _ulp(max(tt, 1.0)))
            tt = base + step
        k += 1
        tq = t1


# ---- one cell -----------------------------------------------------------------------------------

@jit(nrt=False, inline=True)
def grid_next(t, end, h_exc, nsub, dt, h_free, t_lim):
    """The first grid instant after ``t``: during a pulse, multiples of ``h_exc`` up to
    ``end``; during a record, ``nsub`` equal steps per sample (``dt``), the samples exact; after
    the excitation, ``end`` plus multiples of ``h_free``; never beyond ``t_lim``."""
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


@jit(nrt=False)
def run_cell(x, rec, b, s, t_lim, max_impacts, decide, th0, v0, side0, win, imp, traj, out_f,
             out_i):
    """One run from ``(th0, v0)`` on corner ``side0`` (0: at rest): writes ``out_f`` and
    ``out_i`` (``F_*``, ``I_*``). ``imp`` (rows ``t, theta'-, theta'+``) and ``traj`` (rows
    ``t, theta, theta'`` at the grid points and the events) keep what their lengths hold:
    buffers of no rows for a grid, which needs neither."""
    thc, xi, e, thr = b[B_THC], b[B_XI], b[B_E], b[B_COT]
    th_top = b[B_THTOP]
    sthc, cthc = math.sin(thc), math.cos(thc)
    thover, rest_speed = s[S_THOVER], s[S_REST]
    end = x[X_END]
    kind = int(x[X_KIND])
    # the grid: a pulse in X_STEPS equal steps, a record in X_STEPS steps per sample, free
    # rocking in steps of S_HFREE
    nsub = 0
    dt = 0.0
    if kind == K_RECORD:
        nsub = int(x[X_STEPS])
        dt = x[X_DT]
        h_exc = dt / nsub
    else:
        h_exc = end / x[X_STEPS]
    h_free = s[S_HFREE]
    nwin = pulse_windows(x, thr, win) if kind < K_RECORD else 0  # the others: found as needed
    n_imp_buf = imp.shape[0]

    t = 0.0
    th = th0
    v = v0
    side = side0
    a = acc(th, v, t, side, sthc, cthc, xi, x, rec) if side != 0 else 0.0
    n_imp = 0
    n_rest = 0
    n_step = 0
    n_tr = _keep(traj, 0, t, th, v)
    max_th = abs(th0)
    t_over = math.nan
    t_up_first = math.nan
    status = -1
    while status < 0:
        if t >= t_lim:
            status = ST_TIME_LIMIT
            break
        if side == 0:  # ---- at rest ------------------------------------------------------------
            t_up, up = next_uplift(t, x, rec, win, nwin, thc, xi, thr)
            if up == 0:
                status = ST_REST
                break
            if t_up >= t_lim:
                n_tr = _keep(traj, n_tr, t_lim, 0.0, 0.0)
                t = t_lim
                status = ST_TIME_LIMIT
                break
            if t_up > t:
                n_tr = _keep(traj, n_tr, t_up, 0.0, 0.0)
            t = t_up
            if math.isnan(t_up_first):
                t_up_first = t
            side = up
            th = side * _TINY
            v = 0.0
            a = acc(th, v, t, side, sthc, cthc, xi, x, rec)
            continue
        if decide and t >= end and free_rocking_decided(th, v, max_th, thc, th_top):
            status = ST_DECIDED
            break
        # ---- one step on corner `side` --------------------------------------------------------
        tn = grid_next(t, end, h_exc, nsub, dt, h_free, t_lim)
        hh = tn - t
        th1, v1, a1 = dp_step(t, th, v, a, hh, tn, side, sthc, cthc, xi, x, rec)
        n_step += 1
        if not (math.isfinite(th1) and math.isfinite(v1) and math.isfinite(a1)):
            status = ST_NONFINITE
            break
        lo = 0.0
        th_c = 0.0
        # rising at the start (or about to: the instant of an uplift) and falling at the end
        crest = (side * v > 0.0 or (v == 0.0 and side * a > 0.0)) and side * v1 < 0.0
        if crest:  # a maximum of side * theta inside the step
            tau, th_c, vc, ac, ns = locate(1, 0.0, t, th, v, a, 0.0, hh, 1.0, tn, side,
                                           sthc, cthc, xi, x, rec)
            n_step += ns
            max_th = max(max_th, abs(th_c))
            if decide and t + tau >= end and free_rocking_decided(th_c, 0.0, max_th, thc,
                                                                  th_top):
                t = t + tau
                th, v = th_c, vc
                n_tr = _keep(traj, n_tr, t, th, v)
                status = ST_DECIDED
                break
            lo = tau
        impact_at = -1.0
        if side * th1 >= thover:  # overturning
            tau, th2, v2, a2, ns = locate(0, thover, t, th, v, a, 0.0, hh,
                                          side * th - thover, tn, side, sthc, cthc, xi, x, rec)
            n_step += ns
            t = t_over = t + tau
            th, v = th2, v2
            n_tr = _keep(traj, n_tr, t, th, v)
            max_th = max(max_th, thover)
            status = ST_OVERTURNED
            break
        if side * th1 < 0.0:  # an impact inside the step
            impact_at = hh
        elif not crest and side * v < 0.0 and side * v1 > 0.0:
            # a minimum of side * theta: below 0, the block went through an impact and back
            tau, th2, v2, a2, ns = locate(1, 0.0, t, th, v, a, 0.0, hh, side * v, tn, side,
                                          sthc, cthc, xi, x, rec)
            n_step += ns
            if side * th2 < 0.0:
                impact_at = tau
        if impact_at < 0.0:
            if t < end <= tn:  # the excitation ends here: free rocking from f = 0 on
                a1 = acc_free(th1, v1, side, sthc, cthc, xi)
            t = tn
            th, v, a = th1, v1, a1
            n_tr = _keep(traj, n_tr, t, th, v)
            max_th = max(max_th, abs(th))
            continue
        # ---- impact --------------------------------------------------------------------------
        g_lo = side * th if lo == 0.0 else side * th_c
        tau, th2, v2, a2, ns = locate(0, 0.0, t, th, v, a, lo, impact_at, g_lo, tn, side,
                                      sthc, cthc, xi, x, rec)
        n_step += ns
        t = t + tau
        n_tr = _keep(traj, n_tr, t, 0.0, v2)
        dth_p = jump(v2, restitution_at(int(b[B_LAW]), abs(v2), e, b[B_LAW_SHAPE])[0])
        if n_imp < n_imp_buf:
            imp[n_imp, 0] = t
            imp[n_imp, 1] = v2
            imp[n_imp, 2] = dth_p
        n_imp += 1
        side = -side
        th = side * _TINY
        v = dth_p
        if abs(dth_p) < rest_speed or dth_p == 0.0:
            th = 0.0
            v = 0.0
            side = 0
            n_rest += 1
        else:
            a = acc(th, v, t, side, sthc, cthc, xi, x, rec)
        if n_imp >= max_impacts:
            status = ST_MAX_IMPACTS
            break

    if status == ST_OVERTURNED:
        outcome = OC_OVER_IMPACT if n_imp > 0 else OC_OVER_NO_IMPACT
    elif status == ST_REST or status == ST_DECIDED or (status == ST_TIME_LIMIT and t >= end):
        outcome = OC_SAFE
    else:
        outcome = OC_UNRESOLVED
    out_f[TF_MAXROT] = max_th / b[B_ALPHA]
    out_f[TF_TOVER] = t_over
    out_f[TF_T] = t
    out_f[TF_TUP] = t_up_first
    out_f[TF_TH] = th
    out_f[TF_DTH] = v
    out_f[TF_MAXTH] = max_th
    out_i[TI_OUTCOME] = outcome
    out_i[TI_IMPACTS] = n_imp
    out_i[TI_STATUS] = status
    out_i[TI_REST] = n_rest
    out_i[TI_TRAJ] = n_tr
    out_i[TI_STEPS] = n_step


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
    none = np.empty((0, 3))  # no windows given: read only, shared
    for k in prange(per * stride):
        i = (k % per) * stride + k // per
        if i >= n:
            continue
        win = np.empty((3, 3))  # each cell's own scratch
        run_cell(xpar[i], rec, bpar[block_of[i]], spar, t_lim[i], max_impacts, decide, 0.0,
                 0.0, 0, win, none, none, out_f[i], out_i[i])
