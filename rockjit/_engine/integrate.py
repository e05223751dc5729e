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

Where the time goes. A step is six stages in a chain, each waiting for the one before, so its
cost is the chain's latency more than its arithmetic (benchmarks/README.md, "Throughput"). The
block's part of a step is written out stage by stage (:func:`block_step`) so that its values
stay in registers; a stage's angle is kept as an offset from the step's start angle, computed
straight from the accelerations (Nyström's form of the tableau), and enters only a short
polynomial (:func:`rockjit.model.accel_near`); the forcing at the stages of a grid step is
tabulated once per run. The step's pieces are inlined into :func:`_loop` by LLVM (they are
marked ``alwaysinline``: :func:`rockjit._jit.jit`), which is compiled without numba's reference
counting. So are the pieces of an event (:func:`locate`, :func:`impact`, the step after it):
called out of line, each passed its dozen arrays as seven scalars apiece, and the calls, not
the arithmetic, were a third of an event's cost (the study's basin takes 0.70x the time with
them inlined; a cold compile of a variant, 2-6 % longer).

The state lives in one array ``y``: ``theta, theta'``, then ``r, s`` when the oscillator
embedding is integrated, then the 2×2 tangent matrix (column-major) when Lyapunov exponents are
asked for. Which of these exist is decided at compile time by :func:`build`; a run that does not
ask for tangent vectors compiles without them. The compile-time switches
``EMBED4``, ``TANGENT`` (and ``block_step``'s ``SLOPE``) are ``True`` or ``None``, never
``False``, and are tested as ``is not None``: numba prunes a branch before typing it only when
it compares an argument with ``None`` (``numba.core.analysis.dead_branch_prune``), so a run
without tangent vectors or embedding never types, lowers or optimises their code (a cold first
run 11.7 -> 10.2 s). ``False`` would read as on. Recording a trajectory is the one
run-time switch (one test per grid step, in :func:`grid_point`): measured side by side it costs
nothing distinguishable per step, and it halves the variants to compile (benchmarks/bench_compile.py).

Kernels never raise; they return the status codes below, which :mod:`rockjit.single` turns into
messages.

Notes
-----
Tableau and continuous extension: Dormand & Prince (1980), in scipy's ``RK45`` naming
(``A, B, C, E, P``; stages ``K``; FSAL derivative ``K[-1]``).
"""

from __future__ import annotations

import functools
import math
from collections import namedtuple

import numpy as np

from .._jit import cycles, fma, jit
from .classify import orbit_scale, repeats
from ..result import STATUSES
from ..model import (NEAR_RANGE, SINCOS_RANGE, accel_near, accel_pq, corner, forcing_closed, jump,
                    near_poly, oscillator, rotate, saltation, sincos, sincos_poly, slope_pq,
                    uplift_time)
from .stages import chain, compile_step
# the tableau (scipy's names) and the step's table: data of their own module, named here too
from .tableau import (A, B, C, E, N_STAGES, N_TAB, P, T_HAA, T_HB, T_HBA, T_HC,  # noqa: F401
                      T_ROTC, T_ROTS, _AA, _BA, step_table, tab_entry)

# ---- status codes (kernels return these; the Python layer explains them) ----------------------
RUNNING = -1
DONE = 0          # reached the requested end time
OVERTURNED = 1    # |theta| reached the overturning threshold
REST = 2          # at rest, and the forcing can never lift the block again
MAX_IMPACTS = 3   # the impact bound was reached
NONFINITE = 4     # a non-finite number appeared (never expected; a guard, not a result)
SETTLED = 5       # stopped early: the stroboscopic orbit settled (see analysis)

STATUS_NAMES = dict(enumerate(STATUSES))  # code -> name (rockjit.result.STATUSES)

# ---- the kernel's arguments ---------------------------------------------------------------------
# rockjit._engine.kernel is the one module that packs these and reads them back; the layouts below are
# the contract between it and the compiled code.

#: What a run writes: stroboscopic samples at kT and kT + T/2 (rows theta, theta', r, s), the
#: impacts (rows t, theta'-, theta'+; a ring holding the latest when there are more), the
#: recorded trajectory (rows t, theta, theta', r, s), the running exponents at kT (columns
#: lambda1, lambda2 as S(kT)/kT, and the number of collapses of the tangent vectors before kT),
#: the number of impacts before kT, and the scalar outputs ``iout`` and ``fout`` below.
Outputs = namedtuple("Outputs", "strobe half impacts traj lam_run per_imp iout fout")

#: The loop's work arrays: stages ``K``; states ``y, ytmp, ynew, yev``; ``lam`` (sums of the
#: logs of the stretches, overall and in the window); step tables for the grid step (``tab_h``)
#: and for substeps (``tab``); the stage forcing ``fr`` and slopes ``jac``; ``trig``, the sine
#: and cosine of theta at the start and the end of a step; ``ftab``, the closed-form forcing
#: at each grid step of a period (columns ``FT_*`` below).
Work = namedtuple("Work", "K y ytmp ynew yev lam tab_h tab fr jac trig ftab")

# ---- layout of the float parameter vector ``par`` ---------------------------------------------
P_THC, P_XI, P_E, P_AW2, P_OMEGA, P_PHI, P_COT, P_THOVER, P_REST, P_H, P_SETTLE_TOL = range(11)
N_PAR = 11
# ... which the kernel copies into a working vector with constants derived from it:
P_STHC, P_CTHC = range(N_PAR, N_PAR + 2)  # sin(thc), cos(thc)
N_PARW = N_PAR + 2

# ---- layout of the integer settings ``ipar`` ---------------------------------------------------
I_N, I_PERIODS, I_MAXIMP, I_STRIDE, I_WINDOW, I_SETTLE, I_QR, I_PMAX, I_CONTINUE = range(9)
N_IPAR = 9
# I_CONTINUE: 1 to integrate on past the overturning threshold (the study's own runs did; the
# first crossing is recorded in F_TOVER), 0 to stop there (the physical rule, docs/theory/impacts.md).
# I_QR: grid steps between renormalisations of the tangent vectors (0: never).
# I_SETTLE: repetitions of a period that count as settled (0: never stop early); I_PMAX: the
# longest period looked for.

# ---- layout of the integer outputs ``iout`` ----------------------------------------------------
O_STATUS, O_STEPS, O_IMPACTS, O_RHS, O_NSTROBE, O_NHALF, O_NTRAJ, O_NREST, O_NREST_WIN, \
    O_SUBSTEPS, O_NIMP_WIN, O_PERIOD, O_NCOL, O_UNCONVERGED, O_RESTEP = range(15)
N_IOUT = 15
# O_NCOL: collapses of the tangent vectors (rest phases, impacts with e = 0): every perturbation
# died there. O_UNCONVERGED: events whose Newton polish did not reach its tolerance. O_RESTEP:
# events located by genuine steps because the step's interpolant was not trusted (see locate).

# ---- layout of the float outputs ``fout`` ------------------------------------------------------
F_T, F_TH, F_DTH, F_R, F_S, F_MAXERR, F_LAM1, F_LAM2, F_WINTIME, F_V = range(10)
F_TOVER = F_V + 4  # F_V..F_V+3: the tangent matrix at the end, column-major
N_FOUT = F_TOVER + 1  # F_TOVER: the first instant |theta| reached theta_over (nan: never)

# ---- columns of the forcing table ``ftab`` (one row per grid step ``j`` of a period) -----------
# 0..6: the forcing acceleration alpha omega^2 sin(phase) at stage i of step j (6: its end);
# FT_DF0, FT_DF1: its time derivative alpha omega^3 cos(phase) at the step's start and end (the
# jerk and snap of the event interpolant, :func:`end_derivs`); FT_SIN, FT_COS: sin and cos of the
# phase phi + 2 pi j / N at the step's start (a step from an event instant rotates them,
# :func:`phase_before`).
FT_DF0, FT_DF1, FT_SIN, FT_COS = 7, 8, 9, 10
N_FTAB = 11

# Kinds of event.
EV_NONE, EV_IMPACT, EV_OVERTURN, EV_UPLIFT = 0, 1, 2, 3

BISECT_ITERS = 60
NEWTON_ITERS = 8
DELTA_EULER = 1e-8  # see locate_step
LOCATE_TOL = DELTA_EULER  # see locate_interp

# Constants handed to the step's inlined pieces go as int64 and bool values (np.int64(0),
# np.bool_(True), OFF_GRID), not as Python literals: numba types a literal argument by its value
# and compiles the piece once more for each value (a cold start's time), while LLVM folds the
# constant once the piece is inlined either way.
OFF_GRID = np.bool_(False)  # rk_step's ``tabulated`` for a step off the grid (from an event)


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
        code (see :func:`_loop`). Recording is not a switch here: ``out.traj`` with more than
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
def block_stage(FAST, SLOPE, x0, d, v, f, side, par, s0, c0):
    """Acceleration and its slope ``d theta''/d theta`` at angle ``x0 + d`` (:mod:`rockjit.model`).

    ``FAST``: ``s0, c0`` are the sine and cosine of ``x0`` and ``|d| <= NEAR_RANGE`` (the caller
    checks): the corner's coefficients are rotated to ``x0`` and only ``d`` enters a
    polynomial, shorter than a sine's over the whole range. Otherwise the sine and cosine of
    ``x0 + d`` are computed afresh (libm beyond ``SINCOS_RANGE``). Without ``SLOPE`` (no tangent
    dynamics) the fast path returns 0 for the slope.
    """
    P, Q = corner(f, side, par[P_STHC], par[P_CTHC])
    if FAST:
        Pr, Qr = rotate(P, Q, s0, c0)
        a = accel_near(Pr, Qr, d, v, par[P_XI])
        if SLOPE is None:
            return a, 0.0
        sn, cn = near_poly(d)
        return a, slope_pq(Pr, Qr, d * sn, cn)
    s, c = sincos(x0 + d)
    return accel_pq(P, Q, s, c, v, par[P_XI]), slope_pq(P, Q, s, c)


@jit(nrt=False, inline=True)
def rhs(EMBED4, r, y, side, par, K, jac, trig):
    """The field at the step's start into ``K[0]``, the slope into ``jac[0]``, and the sine and
    cosine of theta into ``trig[0:2]``; ``r`` is the closed-form forcing value (ignored with the
    embedding, which reads ``r`` from y). The tangent rows of ``K[0]`` are filled by
    :func:`tangent_step` itself."""
    if EMBED4 is not None:
        r = y[2]
        dr, ds = oscillator(r, y[3], par[P_OMEGA])
        K[0, 2] = dr
        K[0, 3] = ds
    trig[0], trig[1] = sincos(y[0])
    if side == 0:
        K[0, 0] = 0.0
        K[0, 1] = 0.0
        jac[0] = 0.0
    else:
        K[0, 0] = y[1]
        K[0, 1], jac[0] = block_stage(False, True, y[0], 0.0, y[1], par[P_AW2] * r, side, par,
                                      0.0, 0.0)


def _tab_coef(kind, i, j):
    """A coefficient of the chain (:func:`rockjit._engine.stages.chain`) in the step's table."""
    row, col = tab_entry(kind, i, j)
    return f"tab[{row}, {col}]"


#: :func:`block_step`'s source, rendered from the one stage chain
_BLOCK_STEP = (
    ["k0 = K[0, 1]", "s0 = trig[0]", "c0 = trig[1]"]
    + chain(lambda i: f"k{i}, j{i} = block_stage(FAST, SLOPE, x0, x{i}, v{i}, fr[{i}], side, "
                      f"par, s0, c0)", _tab_coef, arith="fma", form="nystrom")
    + ["x6e = x0 + x6",
       "trig[2], trig[3] = sincos_poly(x6e) if FAST else sincos(x6e)",
       "far = max(max(max(abs(x1), abs(x2)), max(abs(x3), abs(x4))), max(abs(x5), abs(x6)))",
       "far = max(far * (1.0 / NEAR_RANGE), abs(x6e) * (1.0 / SINCOS_RANGE))"]
    + [f"K[{i}, 0] = v{i}" for i in range(1, N_STAGES + 1)]
    + [f"K[{i}, 1] = k{i}" for i in range(1, N_STAGES + 1)]
    + ["if SLOPE is not None:"] + [f"    jac[{i}] = j{i}" for i in range(1, N_STAGES + 1)]
    + ["return x6e, v6, far"])

block_step = compile_step(
    "block_step", "FAST, SLOPE, x0, v0, fr, tab, side, par, K, jac, trig", _BLOCK_STEP, globals(),
    jit(nrt=False, inline=True), doc="""The block's ``(theta, theta')`` over one Dormand–Prince step.

    ``K[0, 1]`` holds the acceleration at the start, ``trig[0:2]`` the sine and cosine of
    ``x0``; ``fr[i]`` the forcing acceleration at stage ``i``; ``tab`` the step's table. Fills
    ``K[1:, :2]``, ``jac[1:]`` and ``trig[2:4]`` (at the step's end) and returns
    ``(theta, theta', far)`` at the step's end.

    This is the integrator's critical path: the stage chain in Nystrom's form
    (:mod:`rockjit._engine.stages`), whose stage values stay in registers; the stages' angles
    are offsets ``x_i`` from ``x0`` (:func:`block_stage`). The sine and cosine of the end angle
    (the next step's base) are off the chain. With ``FAST``, ``far > 1`` says an offset
    exceeded ``NEAR_RANGE`` or the end angle ``SINCOS_RANGE``: the caller must redo the step
    without.""")


@jit(nrt=False)
def osc_step(y, K, ytmp, ynew, tab, par, fr):
    """The forcing oscillator ``(r, s)`` over one step (it does not depend on the block); the
    forcing acceleration at each stage into ``fr``. ``K[0, 2:4]`` holds the field at the start."""
    omega = par[P_OMEGA]
    aw2 = par[P_AW2]
    fr[0] = aw2 * y[2]
    for i in range(1, N_STAGES + 1):
        row = i if i < N_STAGES else T_HB
        for m in range(2, 4):
            acc = y[m]
            for j in range(i):
                acc = fma(tab[row, j], K[j, m], acc)
            ytmp[m] = acc
        K[i, 2], K[i, 3] = oscillator(ytmp[2], ytmp[3], omega)
        fr[i] = aw2 * ytmp[2]
    ynew[2] = ytmp[2]
    ynew[3] = ytmp[3]


tangent_column = compile_step(
    "tangent_column", "x0, v0, tab, jac, jb",
    ["k0 = fma(jac[0], x0, jb * v0)"]
    + chain(lambda i: f"k{i} = fma(jac[{i}], x{i}, jb * v{i})", _tab_coef, arith="fma",
            form="first")
    + ["return x6, v6, k6, k0"],
    globals(), jit(nrt=False, inline=True), doc="""One column ``(p, q)`` of the tangent matrix
    over one step, ``p' = q``, ``q' = jac_i p + jb q`` at stage ``i``: the stage chain in its
    first-order form (its stages are independent of the state's chain, so this is throughput,
    not latency). Returns the column at the step's end and its derivative there and at the
    start.""")


@jit(nrt=False, inline=True)
def tangent_step(NS, y, K, ynew, tab, par, jac):
    """The 2×2 tangent matrix (columns at ``y[NS:NS+4]``) over one step: ``V' = J V`` with
    ``J = [[0, 1], [jac, -3/4 xi]]`` at each stage (:func:`block_stage` left the slopes in
    ``jac``). The tangent never feeds back into the state. ``K[0]`` and ``K[-1]`` receive the
    tangent's derivative at the step's ends (the end's is used to carry an event's state the
    last Newton correction, :func:`locate`)."""
    jb = -0.75 * par[P_XI]
    for c in range(2):
        a = NS + 2 * c
        p, q, k6, k0 = tangent_column(y[a], y[a + 1], tab, jac, jb)
        ynew[a] = p
        ynew[a + 1] = q
        K[0, a] = y[a + 1]
        K[0, a + 1] = k0
        K[N_STAGES, a] = q
        K[N_STAGES, a + 1] = k6


@jit(nrt=False, inline=True)
def phase_before(EMBED4, ftab, jn, u):
    """Sine and cosine of the closed-form forcing's phase the angle ``u`` (``omega`` times a
    time within a grid step, ``|u| <= 2 pi / N``) before the start of grid step ``jn`` of the
    period: the table's exact values rotated back, instead of a sine of ``omega t + phi`` (no
    library call, and no rounding of a large ``t``). Zero with the embedding, whose forcing is
    integrated."""
    if EMBED4 is not None:
        return 0.0, 0.0
    su, cu = sincos_poly(u)
    se = ftab[jn, FT_SIN]
    ce = ftab[jn, FT_COS]
    return fma(se, cu, -(ce * su)), fma(ce, cu, se * su)


@jit(nrt=False)
def forcing_at(t, par):
    return forcing_closed(t, par[P_OMEGA], par[P_PHI])


@jit(nrt=False, inline=True)
def rk_step(EMBED4, TANGENT, tabulated, sp, cp, y, K, side, par, ytmp, ynew, tab, fr, jac,
            trig):
    """One Dormand–Prince step from y with the table ``tab`` of its length; ``K[0]`` (and
    ``jac[0]``) must hold the field at the start.

    ``fr`` receives the forcing acceleration at each stage. With ``tabulated`` (closed form, a
    whole grid step) it already holds it. Otherwise ``sp, cp`` are sin and cos of the forcing
    phase ``omega t + phi`` at the step's start, and the closed-form forcing at each stage is
    that pair rotated by the table's phase advances (both are ignored with the embedding).
    """
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    if EMBED4 is not None:
        osc_step(y, K, ytmp, ynew, tab, par, fr)
    elif not tabulated:
        aw2 = par[P_AW2]
        for i in range(N_STAGES + 1):
            fr[i] = aw2 * fma(sp, tab[T_ROTC, i], cp * tab[T_ROTS, i])
    if side == 0:
        for i in range(1, N_STAGES + 1):
            K[i, 0] = 0.0
            K[i, 1] = 0.0
            jac[i] = 0.0
        ynew[0] = y[0]
        ynew[1] = y[1]
    else:
        x, v, far = block_step(True, TANGENT, y[0], y[1], fr, tab, side, par, K, jac, trig)
        if far > 1.0:  # rare: a stage too far from the start, or beyond the sines' polynomial
            x, v, far = block_step(False, TANGENT, y[0], y[1], fr, tab, side, par, K, jac, trig)
        ynew[0] = x
        ynew[1] = v
    if TANGENT is not None:
        tangent_step(NS, y, K, ynew, tab, par, jac)


@jit(nrt=False, inline=True)
def dense_coeffs(K, m):
    """Coefficients of the continuous extension of component m (scipy's ``Q = K.T P``)."""
    q0 = 0.0
    q1 = 0.0
    q2 = 0.0
    q3 = 0.0
    for i in range(N_STAGES + 1):
        k = K[i, m]
        q0 += k * P[i, 0]
        q1 += k * P[i, 1]
        q2 += k * P[i, 2]
        q3 += k * P[i, 3]
    return q0, q1, q2, q3


@jit(nrt=False, inline=True)
def event_g(kind, v, dv, side, par):
    """The event function ``g`` (positive before the event) and its derivative, from the value
    ``v`` of the component it watches (theta; r for an uplift) and that value's derivative
    ``dv`` (with respect to time, or to the step fraction: ``g`` is linear in ``dv``)."""
    if kind == EV_IMPACT:
        return side * v, side * dv
    if kind == EV_OVERTURN:
        return par[P_THOVER] - side * v, -side * dv
    # EV_UPLIFT, only reached with the embedding: |aw2 r| reaches cot(thc)
    sg = 1.0 if v >= 0.0 else -1.0
    return par[P_COT] - par[P_AW2] * abs(v), -par[P_AW2] * sg * dv


@jit(nrt=False)
def event_value(kind, y, side, par):
    """:func:`event_g` at the state ``y``."""
    if kind == EV_UPLIFT:
        dr, _ = oscillator(y[2], y[3], par[P_OMEGA])
        return event_g(kind, y[2], dr, side, par)
    return event_g(kind, y[0], y[1], side, par)


@jit(nrt=False, inline=True)
def dense_event(kind, y0m, h, q0, q1, q2, q3, side, par, x):
    """Event function evaluated on the continuous extension at x = tau/h."""
    g, _ = dense_event_slope(kind, y0m, h, q0, q1, q2, q3, side, par, x)
    return g


@jit(nrt=False, inline=True)
def turning_point(q0, q1, q2, q3, sgn, want_max):
    """x in [0, 1] where sgn * d/dx of the extension changes sign.

    With ``want_max`` the derivative goes from >= 0 to < 0 (a maximum of the signed
    component), otherwise from <= 0 to > 0 (a minimum). When the step's ends bracket the
    change, a safeguarded Newton iteration on the derivative (a cubic) finds it in a few
    iterations; otherwise, or if Newton stalls, bisection (60 halvings, each a branch the
    processor cannot predict, were a third of an event step's time).
    """
    lo = 0.0
    hi = 1.0
    d_lo = sgn * q0
    d_hi = sgn * (q0 + 2.0 * q1 + 3.0 * q2 + 4.0 * q3)
    if (d_lo >= 0.0) == want_max and (d_hi >= 0.0) != want_max:
        # the change is bracketed: start where the derivative's chord crosses zero
        x = d_lo / (d_lo - d_hi)
        if not (0.0 < x < 1.0):
            x = 0.5
        for _ in range(BISECT_ITERS):
            d = sgn * (q0 + x * (2.0 * q1 + x * (3.0 * q2 + x * 4.0 * q3)))
            if d == 0.0:
                return x
            if (d >= 0.0) == want_max:
                lo = x
            else:
                hi = x
            dd = sgn * (2.0 * q1 + x * (6.0 * q2 + x * 12.0 * q3))
            xn = x - d / dd if dd != 0.0 else 0.5 * (lo + hi)
            if not (lo < xn < hi):
                xn = 0.5 * (lo + hi)
            if abs(xn - x) <= 1e-15 or hi - lo <= 1e-15:
                return xn
            x = xn
        return x
    for _ in range(BISECT_ITERS):
        mid = 0.5 * (lo + hi)
        d = sgn * (q0 + mid * (2.0 * q1 + mid * (3.0 * q2 + mid * 4.0 * q3)))
        if (d >= 0.0) == want_max:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@jit(nrt=False, inline=True)
def dense_event_slope(kind, y0m, h, q0, q1, q2, q3, side, par, x):
    """``(g, dg/dx)`` of :func:`event_g` on the continuous extension at ``x = tau/h``."""
    v = y0m + h * x * (q0 + x * (q1 + x * (q2 + x * q3)))
    dv = h * (q0 + x * (2.0 * q1 + x * (3.0 * q2 + x * 4.0 * q3)))
    return event_g(kind, v, dv, side, par)


# ---- the event interpolant ---------------------------------------------------------------------

@jit(nrt=False, inline=True)
def end_derivs(f, df, side, s, c, v, a, par):
    """The third and fourth derivatives of theta in time (jerk and snap) at a point of a step
    on corner ``side``.

    From the forcing acceleration ``f`` there and its time derivative ``df``, the sine and
    cosine ``s, c`` of theta, ``v = theta'`` and ``a = theta''``. With
    ``theta'' = P cos(theta) + Q sin(theta) - k theta'`` (:func:`rockjit.model.corner`,
    ``k = 3/4 xi``), ``P`` and ``Q`` affine in ``f`` (``dP/df = a1 = 3/4 sin(thc)``,
    ``dQ/df = a2 = 3/4 side cos(thc)``) and ``f'' = -omega^2 f`` (the closed form)::

        jerk = (a1 c + a2 s) f' + (Q c - P s) v - k a
        snap = 2 (a2 c - a1 s) f' v + (a1 c + a2 s) f'' - (a + k v) v^2 + (Q c - P s) a - k jerk

    (``P c + Q s = a + k v``; ``Q c - P s`` is :func:`rockjit.model.slope_pq`).
    """
    a1 = 0.75 * par[P_STHC]
    a2 = 0.75 * (side * par[P_CTHC])
    k = 0.75 * par[P_XI]
    P, Q = corner(f, side, par[P_STHC], par[P_CTHC])
    dadf = fma(a1, c, a2 * s)
    dadf_th = fma(a2, c, -(a1 * s))
    sl = slope_pq(P, Q, s, c)
    j = fma(dadf, df, fma(sl, v, -(k * a)))
    ddf = -(par[P_OMEGA] * par[P_OMEGA]) * f
    sn = fma(2.0 * dadf_th * df, v,
             fma(dadf, ddf, fma(sl, a, fma(-fma(k, v, a) * v, v, -(k * j)))))
    return j, sn


@jit(nrt=False, inline=True)
def hermite7(p0, p1, p2, p3, q0, q1, q2, q3):
    """``c4 .. c7`` of the two-point Hermite polynomial ``sum_k c_k x^k`` of degree 7 on
    ``[0, 1]`` whose value and first three derivatives are ``p0 .. p3`` at 0 and ``q0 .. q3``
    at 1 (derivatives in ``x``: ``h^k`` times those in time); ``c0 .. c3`` are
    ``p0, p1, p2 / 2, p3 / 6``."""
    d = q0 - p0
    c4 = (210.0 * d - 120.0 * p1 - 30.0 * p2 - 4.0 * p3 - 90.0 * q1 + 15.0 * q2 - q3) / 6.0
    c5 = (-168.0 * d + 90.0 * p1 + 20.0 * p2 + 2.0 * p3 + 78.0 * q1 - 14.0 * q2 + q3) / 2.0
    c6 = (420.0 * d - 216.0 * p1 - 45.0 * p2 - 4.0 * p3 - 204.0 * q1 + 39.0 * q2
          - 3.0 * q3) / 6.0
    c7 = (-120.0 * d + 60.0 * p1 + 12.0 * p2 + p3 + 60.0 * q1 - 12.0 * q2 + q3) / 6.0
    return c4, c5, c6, c7


@jit(nrt=False, inline=True)
def poly7(c0, c1, c2, c3, c4, c5, c6, c7, x):
    """``sum_k c_k x^k`` (Estrin's scheme: half the dependency depth of Horner's)."""
    x2 = x * x
    return fma(fma(fma(c7, x, c6), x2, fma(c5, x, c4)), x2 * x2,
               fma(fma(c3, x, c2), x2, fma(c1, x, c0)))


@jit(nrt=False, inline=True)
def poly6(c0, c1, c2, c3, c4, c5, c6, x):
    """``sum_k c_k x^k`` (Estrin's scheme)."""
    x2 = x * x
    return fma(fma(c6, x2, fma(c5, x, c4)), x2 * x2, fma(fma(c3, x, c2), x2, fma(c1, x, c0)))


@jit(nrt=False, inline=True)
def interpolant(y, ynew, hh, K, side, par, trig, f0, df0, f1, df1):
    """The step's own interpolant: Hermite polynomials in ``x = tau / hh`` of degree 7 through
    the step's ends (``y`` at ``x = 0``, ``ynew`` at 1; stages in ``K``, sines and cosines of
    theta at the ends in ``trig``; ``f0, df0`` and ``f1, df1`` the forcing and its time
    derivative at the ends).

    Returns ``(tc, vc, cint, dfc)``: the coefficients ``c0 .. c7`` of theta (through theta and
    its first three derivatives at both ends, :func:`end_derivs`) and of theta' (through theta'
    and its first three derivatives); ``cint``, the estimated constant ``C`` of theta's
    interpolation error ``C x^4 (1 - x)^4`` (Hermite's remainder, ``h^8 theta^(8) / 8!``): the
    septic's fourth derivative less the snap at each end is ``-24 C`` there, the larger taken;
    and ``dfc``, the defect of theta's end value against the integral of theta' by the
    Hermite-Obreschkoff quadrature of the ends' derivatives (exact to degree 7),
    ``th1 - th0 - h (v0 + v1) / 2 - 3/28 h^2 (a0 - a1) - h^3 / 84 (j0 + j1)
    - h^4 / 1680 (s0 - s1)``: of order h^6, an estimate of the end value's error (measured
    within a factor 1.2 of it on a smooth segment from N = 16 on, and within a factor 2 on the
    steps before impacts from N = 64 on; the embedded estimate is of order h^5 and 50-200
    times larger).
    """
    th0 = y[0]
    th1 = ynew[0]
    v0 = y[1]
    v1 = ynew[1]
    a0 = K[0, 1]
    a1 = K[N_STAGES, 1]
    j0, s0 = end_derivs(f0, df0, side, trig[0], trig[1], v0, a0, par)
    j1, s1 = end_derivs(f1, df1, side, trig[2], trig[3], v1, a1, par)
    h2 = hh * hh
    h3 = h2 * hh
    p1 = hh * v0
    p2 = h2 * a0
    p3 = h3 * j0
    q1 = hh * v1
    t4, t5, t6, t7 = hermite7(th0, p1, p2, p3, th1, q1, h2 * a1, h3 * j1)
    u1 = hh * a0
    u2 = h2 * j0
    u3 = h3 * s0
    w3 = h3 * s1
    v4, v5, v6, v7 = hermite7(v0, u1, u2, u3, v1, hh * a1, h2 * j1, w3)
    dfc = th1 - th0 - (0.5 * (p1 + q1) + (3.0 / 28.0) * (p2 - h2 * a1)
                       + (1.0 / 84.0) * (p3 + h3 * j1) + (hh / 1680.0) * (u3 - w3))
    # theta's fourth derivative in x at the ends, on the septic, against the snaps there
    d40 = fma(24.0, t4, -(hh * u3))
    d41 = fma(24.0, t4, fma(120.0, t5, fma(360.0, t6, fma(840.0, t7, -(hh * w3)))))
    cint = max(abs(d40), abs(d41)) / 24.0
    return ((th0, p1, 0.5 * p2, p3 / 6.0, t4, t5, t6, t7),
            (v0, u1, 0.5 * u2, u3 / 6.0, v4, v5, v6, v7), cint, dfc)


@jit(nrt=False, inline=True)
def interp_error(cint, dfc, x):
    """The error estimate of theta on the interpolant at ``x`` (:func:`interpolant`'s
    ``cint, dfc``): the interpolation error ``cint x^4 (1 - x)^4`` plus the end state's,
    ``|dfc|`` weighted by the septic's basis function of the end value,
    ``x^4 (35 - 84 x + 70 x^2 - 20 x^3)``."""
    xx = x * (1.0 - x)
    x4 = (x * x) * (x * x)
    w = x4 * fma(fma(fma(-20.0, x, 70.0), x, -84.0), x, 35.0)
    return fma(cint, (xx * xx) * (xx * xx), w * abs(dfc))


@jit(nrt=False)
def interp_at(y, ynew, hh, K, side, par, trig, f0, df0, f1, df1, x):
    """theta, theta' and the error estimate of the step's interpolant at ``x`` (for tests and
    benchmarks: :func:`interpolant`, :func:`interp_error`)."""
    tc, vc, cint, dfc = interpolant(y, ynew, hh, K, side, par, trig, f0, df0, f1, df1)
    return (poly7(tc[0], tc[1], tc[2], tc[3], tc[4], tc[5], tc[6], tc[7], x),
            poly7(vc[0], vc[1], vc[2], vc[3], vc[4], vc[5], vc[6], vc[7], x),
            interp_error(cint, dfc, x))


@jit(nrt=False, inline=True)
def newton_bracketed(x, g, dg, a, b, conv):
    """One step of the safeguarded Newton iteration for the root of ``g`` in the bracket
    ``[a, b]`` (``g > 0`` at ``a``, ``g <= 0`` at ``b``), from ``x`` where ``g`` and its
    derivative are ``g, dg``. Returns ``(x, a, b, done)``: the bracket narrowed to ``x``; done
    when ``g`` is 0 there, when Newton's step is below ``conv`` and stays in the bracket (it may
    land on its end), or when the bracket has shrunk to 1e-15; a step that leaves the bracket
    bisects it instead."""
    if g > 0.0:
        a = x
    elif g < 0.0:
        b = x
    else:
        return x, a, b, True
    xn = x - g / dg if dg != 0.0 else 0.5 * (a + b)
    if abs(xn - x) <= conv and a <= xn <= b:
        return xn, a, b, True
    if not (a < xn < b):
        xn = 0.5 * (a + b)
    return xn, a, b, b - a <= 1e-15


@jit(nrt=False, inline=True)
def locate_interp(kind, y, ynew, hh, lo, hi, K, side, par, trig, f0, df0, f1, df1):
    """The event in ``[lo, hi]`` on the step's own interpolant, without a field evaluation.

    Over the step, theta is taken as the Hermite polynomial of degree 7 of theta, theta',
    theta'' and theta''' at the step's two ends, and theta' as the one of theta', theta'',
    theta''' and theta'''' (:func:`end_derivs`; ``f0, df0`` and ``f1, df1`` are the forcing and
    its derivative at the ends, ``trig`` the sines and cosines of theta there). Each matches
    the ends' data to degree 7, so within the step it carries the error of the end state (the
    step's own, of order h^6) plus an interpolation error of order h^8. A safeguarded Newton
    iteration finds the root of the event function on it, started from the root of the step's
    start's quadratic Taylor polynomial (2.5 iterations an event on the study's basin; from
    regula falsi, 7.8: a flight that starts on theta = 0 is bracketed from its apex, where
    Newton's steps leave the bracket).

    Its error at the root is estimated from the step's own data (below): the interpolation
    error, and the end state's error weighted by the septic's basis function of the end value.
    Divided by ``|theta'|`` there, it is an estimate of the event time's error; the interpolant
    is trusted when that is at most ``LOCATE_TOL * hh`` (1e-8 h, the size of the last Newton
    correction that the genuine steps carry along the field, :data:`DELTA_EULER`). Measured:
    on a smooth segment the estimate is 1.0-1.7 times the true error of theta from N = 16 on;
    on the study's basin at N = 64 all but 2 in 100 000 events pass, and every event of the
    event-accuracy orbits from N = 32 on; at N = 16 most of them fail, and so do the events
    early in a coarse step with a slow crossing, where a genuine step of the event's own (short)
    length is the more accurate (tests/test_integrate.py: the dips through 0 at N = 16).

    Returns ``(ok, x, theta, theta')``: ``x = tau / hh`` and the state there; ``ok`` is 1 when
    trusted, 0 when not (``x`` then starts the genuine steps' Newton iteration,
    :func:`locate_step`), -1 when the interpolant does not bracket the event as the step's
    data did.
    """
    tc, vc, cint, dfc = interpolant(y, ynew, hh, K, side, par, trig, f0, df0, f1, df1)
    # the event function g (positive before the event) on the interpolant, as a polynomial:
    # sg theta + g_off, and its derivative's coefficients
    sg = float(side) if kind == EV_IMPACT else -float(side)
    g0 = fma(sg, tc[0], par[P_THOVER] if kind == EV_OVERTURN else 0.0)
    g1 = sg * tc[1]
    g2 = sg * tc[2]
    g3 = sg * tc[3]
    g4 = sg * tc[4]
    g5 = sg * tc[5]
    g6 = sg * tc[6]
    g7 = sg * tc[7]
    d2 = 2.0 * g2
    d3 = 3.0 * g3
    d4 = 4.0 * g4
    d5 = 5.0 * g5
    d6 = 6.0 * g6
    d7 = 7.0 * g7
    a = lo / hh
    b = hi / hh
    ga = poly7(g0, g1, g2, g3, g4, g5, g6, g7, a)
    gb = poly7(g0, g1, g2, g3, g4, g5, g6, g7, b)
    if not (ga > 0.0 and gb <= 0.0):
        return -1, 0.0, 0.0, 0.0
    # a start: the root in the bracket of the quadratic g0 + g1 x + g2 x^2 (the step's start's
    # Taylor polynomial: it finds the far root of a flight that starts on g = 0), else regula
    # falsi; then Newton, stopped once its step is below 1e-9 (the next would be below 1e-17:
    # it converges quadratically); a step that leaves the bracket bisects it
    x = -1.0
    disc = fma(g1, g1, -4.0 * g0 * g2)
    if disc >= 0.0 and g2 != 0.0:
        qq = -0.5 * (g1 + math.copysign(math.sqrt(disc), g1))
        if qq != 0.0:
            r1 = qq / g2
            r2 = g0 / qq
            if a < r2 < b:
                x = r2
            elif a < r1 < b:
                x = r1
    if x < 0.0:
        x = a + ga * (b - a) / (ga - gb)
        if not (a < x < b):
            x = 0.5 * (a + b)
    for _ in range(BISECT_ITERS):
        x, a, b, done = newton_bracketed(x, poly7(g0, g1, g2, g3, g4, g5, g6, g7, x),
                                         poly6(g1, d2, d3, d4, d5, d6, d7, x), a, b, 1e-9)
        if done:
            break
    th = poly7(tc[0], tc[1], tc[2], tc[3], tc[4], tc[5], tc[6], tc[7], x)
    v = poly7(vc[0], vc[1], vc[2], vc[3], vc[4], vc[5], vc[6], vc[7], x)
    err = interp_error(cint, dfc, x)
    return 1 if err <= LOCATE_TOL * hh * abs(v) else 0, x, th, v


@jit(nrt=False, inline=True)
def locate(EMBED4, TANGENT, kind, y, ynew, hh, lo, hi, K, side, par, ytmp, yev, counts, tab,
           fr, jac, trig, sp, cp, f0, df0, f1, df1):
    """Time ``tau`` in ``(lo, hi]`` of the event found in the step just taken (of length
    ``hh`` from the state ``y`` to ``ynew``, stages in ``K``), with the state there in ``yev``.

    With the closed-form forcing, on the step's own interpolant (:func:`locate_interp`), which
    costs no evaluation of the field; tangent vectors are then carried to ``tau`` by a genuine
    step of that length (the block's state is the interpolant's either way, so that the
    trajectory does not depend on the switch). Where the interpolant's error estimate says no
    (counted in ``O_RESTEP``), and with the embedding, by genuine steps (:func:`locate_step`).
    ``sp, cp``: sine and cosine of the forcing phase at the step's start; ``f0, df0, f1,
    df1``: the forcing and its time derivative at the step's start and end.
    """
    if EMBED4 is None:
        ok, x, th, v = locate_interp(kind, y, ynew, hh, lo, hi, K, side, par, trig, f0, df0,
                                     f1, df1)
        if ok > 0:
            tau = x * hh
            if TANGENT is not None:
                step_table(par[P_OMEGA], tau, tab)
                rk_step(EMBED4, TANGENT, OFF_GRID, sp, cp, y, K, side, par, ytmp, yev, tab, fr,
                        jac, trig)
                counts[O_RHS] += N_STAGES
            yev[0] = th
            yev[1] = v
            return tau
        counts[O_RESTEP] += 1
        if ok == 0:  # the interpolant's root starts the genuine steps' Newton iteration
            return locate_step(EMBED4, TANGENT, kind, y, hh, lo, hi, K, side, par, ytmp, yev,
                               counts, tab, fr, jac, trig, sp, cp, x)
    return locate_step(EMBED4, TANGENT, kind, y, hh, lo, hi, K, side, par, ytmp, yev, counts,
                       tab, fr, jac, trig, sp, cp, -1.0)


@jit(nrt=False)
def locate_step(EMBED4, TANGENT, kind, y, hh, lo, hi, K, side, par, ytmp, yev, counts, tab,
                fr, jac, trig, sp, cp, x0):
    """:func:`locate` by genuine steps (``sp, cp``: sine and cosine of the forcing phase at the
    step's start).

    1. ``tau0 = x0 * hh`` (the interpolant's root) when ``x0 >= 0``; otherwise a safeguarded
       Newton iteration on the step's continuous extension (K holds its stages), inside the
       bracket ``[lo, hi]`` (g > 0 at lo, g <= 0 at hi), gives ``tau0``: its error is the
       extension's, ~1e-9 h at N = 64.
    2. A genuine 5th-order step of length ``tau0`` from y gives the state there and the event
       function's value and slope: Newton's correction ``delta``. While ``|delta|`` is larger
       than ``DELTA_EULER * hh`` the step is re-taken at the corrected time; once it is
       smaller, the state is carried the last ``delta`` along the field at the end of the step
       (``K[-1]``, first same as last): the error of that, ``delta^2 / 2`` times the state's
       second derivative, is below 1e-18 h^2 (measured: ``|delta|`` is 1e-11 h at N = 256 and
       6e-9 h at N = 64, so one re-step is the rule).
    """
    if x0 >= 0.0:
        tau = x0 * hh
    else:
        comp = 2 if kind == EV_UPLIFT else 0
        q0, q1, q2, q3 = dense_coeffs(K, comp)
        a = lo / hh
        b = hi / hh
        ga, _ = dense_event_slope(kind, y[comp], hh, q0, q1, q2, q3, side, par, a)
        gb, _ = dense_event_slope(kind, y[comp], hh, q0, q1, q2, q3, side, par, b)
        # regula falsi for a start, then Newton; a step that leaves the bracket bisects it
        x = a + ga * (b - a) / (ga - gb) if ga - gb > 0.0 else 0.5 * (a + b)
        if not (a < x < b):
            x = 0.5 * (a + b)
        for _ in range(BISECT_ITERS):
            g, dg = dense_event_slope(kind, y[comp], hh, q0, q1, q2, q3, side, par, x)
            x, a, b, done = newton_bracketed(x, g, dg, a, b, 1e-15)
            if done:
                break
        tau = x * hh
    lo_b = lo
    hi_b = hi
    NY = yev.shape[0]
    for it in range(NEWTON_ITERS):
        step_table(par[P_OMEGA], tau, tab)
        rk_step(EMBED4, TANGENT, OFF_GRID, sp, cp, y, K, side, par, ytmp, yev, tab, fr, jac, trig)
        counts[O_RHS] += N_STAGES
        g, dg = event_value(kind, yev, side, par)
        if g == 0.0:
            break
        if g > 0.0:
            lo_b = tau
        else:
            hi_b = tau
        delta = -g / dg if dg != 0.0 else math.inf
        if abs(delta) <= DELTA_EULER * hh and lo_b <= tau + delta <= hi_b:
            for m in range(NY):
                yev[m] = fma(delta, K[N_STAGES, m], yev[m])
            tau = tau + delta
            break
        tn = tau + delta
        if not (lo_b <= tn <= hi_b):
            tn = 0.5 * (lo_b + hi_b)
        if it == NEWTON_ITERS - 1:
            counts[O_UNCONVERGED] += 1  # taken at the best bracketed estimate; reported
            break
        tau = tn
    return tau  # yev holds the state at this tau


@jit(nrt=False, inline=True)
def detect(y, ynew, hh, K, side, par):
    """Look for an event in the step just taken; returns (kind, lo, hi)."""
    if side == 0:
        # At rest (embedding only): does |f| reach cot(thc) in the step?
        aw2 = par[P_AW2]
        cot = par[P_COT]
        if aw2 * abs(ynew[2]) > cot:
            return EV_UPLIFT, 0.0, hh
        sg = 1.0 if y[2] >= 0.0 else -1.0
        if sg * K[0, 2] > 0.0 and sg * K[N_STAGES, 2] < 0.0:
            q0, q1, q2, q3 = dense_coeffs(K, np.int64(2))
            x = turning_point(q0, q1, q2, q3, sg, np.bool_(True))
            if dense_event(np.int64(EV_UPLIFT), y[2], hh, q0, q1, q2, q3, side, par, x) < 0.0:
                return EV_UPLIFT, 0.0, x * hh
        return EV_NONE, 0.0, 0.0
    g0 = side * y[0]
    g1 = side * ynew[0]
    if g1 >= par[P_THOVER]:
        return EV_OVERTURN, 0.0, hh
    d0 = side * y[1]
    d1 = side * ynew[1]
    if g1 < 0.0:
        if g0 > 0.0:
            return EV_IMPACT, 0.0, hh
        # started on theta = 0 (just after an impact or an uplift): bracket from the apex
        q0, q1, q2, q3 = dense_coeffs(K, np.int64(0))
        x = turning_point(q0, q1, q2, q3, float(side), np.bool_(True))
        if dense_event(np.int64(EV_IMPACT), y[0], hh, q0, q1, q2, q3, side, par, x) > 0.0:
            return EV_IMPACT, x * hh, hh
        return EV_IMPACT, 0.0, 0.0  # a flight too small to resolve: lo == hi marks it
    if g0 > 0.0 and d0 < 0.0 and d1 > 0.0:
        # grazing: theta may dip through 0 and come back within the step
        q0, q1, q2, q3 = dense_coeffs(K, np.int64(0))
        x = turning_point(q0, q1, q2, q3, float(side), np.bool_(False))
        if dense_event(np.int64(EV_IMPACT), y[0], hh, q0, q1, q2, q3, side, par, x) < 0.0:
            return EV_IMPACT, 0.0, x * hh
    return EV_NONE, 0.0, 0.0


@jit(nrt=False)
def forcing_now(EMBED4, t, y, par):
    if EMBED4 is not None:
        return y[2]
    return forcing_closed(t, par[P_OMEGA], par[P_PHI])


@jit(nrt=False)
def sample(EMBED4, t, y, par, out):
    out[0] = y[0]
    out[1] = y[1]
    if EMBED4 is not None:
        out[2] = y[2]
        out[3] = y[3]
    else:
        psi = par[P_OMEGA] * t + par[P_PHI]
        out[2] = math.sin(psi)
        out[3] = math.cos(psi)


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
    return _loop(EMBED4, TANGENT, record, y0, side0, par, ipar, out, w)


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
            ph0 = par[P_PHI] + 2.0 * math.pi * j / n_per
            s0 = math.sin(ph0)
            c0 = math.cos(ph0)
            ftab[j, FT_SIN] = s0
            ftab[j, FT_COS] = c0
            ftab[j, FT_DF0] = aw3 * c0
            for i in range(N_STAGES + 1):
                c = C[i] if i < N_STAGES else 1.0
                sd, cd = sincos(2.0 * math.pi * c / n_per)
                ftab[j, i] = aw2 * fma(s0, cd, c0 * sd)
                if i == N_STAGES:
                    ftab[j, FT_DF1] = aw3 * fma(c0, cd, -(s0 * sd))


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
        # the block leaves rest when the forcing alone says (see _loop, rest phases)
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
        t_up = uplift_time(t, par[P_AW2], par[P_COT], par[P_OMEGA], par[P_PHI])
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
    if par[P_AW2] * max(1.0, rad) <= par[P_COT]:
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

    It takes the compile-time switches, not the state's sizes: compiled on its own with sizes
    unknown, LLVM vectorised its copies behind run-time overlap checks before inlining it, and
    a run with exponents took 9 % longer a step (found by bisecting the commits)."""
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
    latest uplift (then it is held to the grid point, see :func:`_loop`).
    """
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    y = w.y
    e = par[P_E]
    dth_m = y[1]
    dth_p = jump(dth_m, e)
    if TANGENT is not None:
        if dth_m != 0.0:
            s10 = saltation(dth_m, par[P_AW2] * (y[2] if EMBED4 is not None else r), side,
                            par[P_THC], par[P_XI], e)
        else:
            s10 = 0.0
        for c in range(2):
            v0 = y[NS + 2 * c]
            v1 = y[NS + 2 * c + 1]
            y[NS + 2 * c] = e * v0
            y[NS + 2 * c + 1] = s10 * v0 + e * v1
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


@jit(nrt=False, inline=True)
def grid_step(EMBED4, TANGENT, record, PROF, pre, t, side, n_imp, step, j_per, k_per, j_qr,
              j_rec, n_col, n_col_win, t_lift, max_err, par, ipar, out, w, counts):
    """One grid step, from ``t`` (the grid point ``step h``, or the block still at rest) to the
    next grid point (docs/theory/integrator.md): a step of the current corner, or of rest; an event in it is
    located, the state taken there (impact: :func:`impact`; uplift; overturning ends the run),
    and the step finished from the event to the grid point; then :func:`grid_point`.

    The loop's state goes in and comes back out: ``(status, t, side, n_imp, step, j_per, k_per,
    j_qr, j_rec, n_col, n_col_win, t_lift, max_err)``. The one step of the single-lane loop
    (:func:`_loop`) and of a lane taken out of the lanes' lockstep (:mod:`rockjit._engine.lanes`): with
    ``pre`` the grid step's first Runge–Kutta step is already in ``K``, ``w.ynew``, ``w.jac``
    and ``w.trig``. With ``PROF``, ``counts[6:13]`` receive the cycles spent in rest phases,
    in the steps after an event, in locating, in impacts, in detection, in the first step and
    at the grid point (the lanes' accounting, a run-time bool; the single-lane loop passes
    ``PROF = None``: :func:`tick`).
    """
    NS = 4 if EMBED4 is not None else 2  # state: theta, theta' (, r, s)
    NY = NS + (4 if TANGENT is not None else 0)  # plus the tangent matrix, column-major
    h = par[P_H]
    y = w.y
    K = w.K
    status = RUNNING
    j = j_per
    t_grid = (step + 1) * h
    in_window = step >= ipar[I_WINDOW] * ipar[I_N]
    fresh = True  # no event yet in this grid step
    ftab = w.ftab
    jn = j + 1 if j + 1 < ipar[I_N] else 0  # the grid point's row of the forcing table
    sp = 0.0  # sine and cosine of the forcing phase at t, off the grid point (phase_before)
    cp = 0.0
    # Held at rest until the grid point: set when a flight that began at an uplift ends at
    # rest within rounding of that instant (forcing a hair above the uplift threshold, where
    # the acceleration rounds to zero); otherwise the uplift would be found again at the
    # same instant forever (found by the stress suite).
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
                sp, cp = phase_before(EMBED4, ftab, jn, par[P_OMEGA] * (t_grid - t))
                continue
        if fresh:
            # a whole grid step: the forcing phase there is phi + 2 pi j / N exactly
            hh = h
            if not pre:
                c0 = tick(PROF)
                rk_step(EMBED4, TANGENT, EMBED4 is None, 0.0, 0.0, y, K, side, par, w.ytmp, w.ynew,
                        w.tab_h, w.fr if EMBED4 is not None else ftab[j], w.jac, w.trig)
                tock(PROF, counts, np.int64(11), c0)
            pre = False
            # the forcing's phase at the start, its value and derivative at the ends (locate)
            sp = ftab[j, FT_SIN]
            cp = ftab[j, FT_COS]
            f0 = ftab[j, 0]
            df0 = ftab[j, FT_DF0]
            f1 = ftab[j, N_STAGES]
        else:
            c0 = tick(PROF)
            hh = t_grid - t
            step_table(par[P_OMEGA], hh, w.tab)
            rk_step(EMBED4, TANGENT, OFF_GRID, sp, cp, y, K, side, par, w.ytmp, w.ynew, w.tab,
                    w.fr, w.jac, w.trig)
            tock(PROF, counts, np.int64(7), c0)
            f0 = w.fr[0]
            df0 = par[P_AW2] * par[P_OMEGA] * cp
            f1 = w.fr[N_STAGES]
        out.iout[O_RHS] += N_STAGES
        out.iout[O_SUBSTEPS] += 1
        c0 = tick(PROF)
        kind, lo, hi = detect(y, w.ynew, hh, K, side, par)
        tock(PROF, counts, np.int64(10), c0)
        if hold and kind == EV_UPLIFT:
            kind = EV_NONE
        if kind == EV_NONE:
            max_err = accept(EMBED4, TANGENT, side, hh, max_err, w)
            t = t_grid
            break
        c0 = tick(PROF)
        if hi > lo:
            tau = locate(EMBED4, TANGENT, kind, y, w.ynew, hh, lo, hi, K, side, par, w.ytmp,
                         w.yev, out.iout, w.tab, w.fr, w.jac, w.trig, sp, cp, f0, df0, f1,
                         ftab[j, FT_DF1])
        else:
            # an unresolvably small flight: take it as ending at rest where it started
            tau = 0.0
            for m in range(NY):
                w.yev[m] = y[m]
            w.yev[1] = 0.0
        tock(PROF, counts, np.int64(8), c0)
        t = t + tau
        fresh = False
        for m in range(NY):
            y[m] = w.yev[m]
        # the forcing phase at the event, for the rest of the step (and its forcing)
        sp, cp = phase_before(EMBED4, ftab, jn, par[P_OMEGA] * (t_grid - t))
        if kind == EV_OVERTURN:
            if ipar[I_CONTINUE] == 0:
                status = OVERTURNED
                break
            # the study's way: note the first crossing and integrate on (the same field;
            # the threshold is lifted so that the crossing is not found again)
            out.fout[F_TOVER] = t
            par[P_THOVER] = math.inf
            rhs(EMBED4, forcing_at(t, par), y, side, par, K, w.jac, w.trig)
            out.iout[O_RHS] += 1
            continue
        if kind == EV_UPLIFT:
            y[0] = 0.0
            y[1] = 0.0
            side = 1 if y[2] > 0.0 else -1
            t_lift = t
            rhs(EMBED4, forcing_at(t, par), y, side, par, K, w.jac, w.trig)
            out.iout[O_RHS] += 1
            continue
        c0 = tick(PROF)
        side, n_imp, rests, held = impact(EMBED4, TANGENT, t, sp, t_lift, side, n_imp,
                                          in_window, par, out, w)
        tock(PROF, counts, np.int64(9), c0)
        if rests:
            hold = hold or held
            if TANGENT is not None:
                # A rest phase ends every perturbation: a nearby state reaches rest too (its
                # Zeno cascade ends a little earlier or later), and the block leaves rest
                # when the forcing alone says. The flow's Jacobian across it is zero, and
                # the exponents of a stretch holding one are -inf (docs/theory/exponents.md). (Banking the
                # vectors' growth instead counted the cascade's saltation entries, ~1/theta'
                # at the last impacts, as growth: exponents that depended on rest_speed.)
                reset_tangent(EMBED4, y)
                n_col += 1
                if in_window:
                    n_col_win += 1
        if n_imp >= ipar[I_MAXIMP]:
            status = MAX_IMPACTS
            break
    if status == RUNNING:
        step += 1
        if not (math.isfinite(y[0]) and math.isfinite(y[1])):
            status = NONFINITE
        else:
            c0 = tick(PROF)
            status, j_per, k_per, j_qr, j_rec, collapsed = grid_point(
                EMBED4, TANGENT, record, t, step, side, n_imp, n_col, in_window, ipar, par,
                out, w, j_per, k_per, j_qr, j_rec)
            tock(PROF, counts, np.int64(12), c0)
            if collapsed:
                n_col += 1
                if in_window:
                    n_col_win += 1
    return (status, t, side, n_imp, step, j_per, k_per, j_qr, j_rec, n_col, n_col_win, t_lift,
            max_err)


@jit(nrt=False)
def _loop(EMBED4, TANGENT, record, y0, side0, par, ipar, out, w):
    """The integration: ``_run``'s arguments, the parameters with the derived constants
    (``N_PARW``), and the :data:`Work` arrays ``w``; grid step by grid step
    (:func:`grid_step`) to the end, then :func:`finish`."""
    n_per = ipar[I_N]
    total = n_per * ipar[I_PERIODS]
    status = start(EMBED4, TANGENT, y0, side0, par, ipar, out, w)
    side = side0
    t = 0.0
    max_err = 0.0
    # the counters start as int64, not as the literal 0: numba would type (and compile) every
    # piece they are passed to once more for the literal
    n_imp = np.int64(0)
    step = np.int64(0)
    j_per = np.int64(0)  # grid steps into the current period
    k_per = np.int64(0)  # completed periods
    j_qr = np.int64(0)
    j_rec = np.int64(0)
    n_col = out.iout[O_NCOL]  # collapses of the tangent vectors (start at rest; see below)
    n_col_win = n_col if ipar[I_WINDOW] == 0 else 0
    t_lift = -math.inf  # instant of the latest uplift
    while step < total and status == RUNNING:
        (status, t, side, n_imp, step, j_per, k_per, j_qr, j_rec, n_col, n_col_win, t_lift,
         max_err) = grid_step(EMBED4, TANGENT, record, None, False, t, side, n_imp, step,
                              j_per, k_per, j_qr, j_rec, n_col, n_col_win, t_lift, max_err,
                              par, ipar, out, w, out.iout)
    if status == RUNNING:
        status = DONE
    out.iout[O_NCOL] = n_col
    finish(EMBED4, TANGENT, status, t, step, n_imp, n_col_win, max_err, ipar, par, out, w)
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
