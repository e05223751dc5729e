"""The steps: the harmonic kernels' Dormand–Prince step of the block, the forcing oscillator's
and the tangent matrix's, and the continuous extension's coefficients; the transient kernel's
step of the block under an excitation plug (:func:`dp_step`).

The stage chain itself is :mod:`rockjit._engine.stages`' (rendered here for the block and
for a tangent column); the tableau and the step's table, :mod:`rockjit._engine.tableau`.
"""

from __future__ import annotations

from .._jit import fma, jit
from ..model import (NEAR_RANGE, SINCOS_RANGE, accel_near, accel_pq, corner, damping_rate,
                     near_poly, rotate, sincos, sincos_poly, slope_pq)
from ..plugs import harmonic, plug_value
from ..plugs.harmonic import oscillator
from .layout import FT_COS, FT_SIN, P_AW2, P_CTHC, P_OMEGA, P_PHI, P_STHC, P_XI
from .stages import chain, compile_step, node
from .tableau import A, N_STAGES, P, T_HB, T_ROTC, T_ROTS, tab_entry


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
    last Newton correction, :func:`rockjit._engine.events.locate_step`)."""
    jb = -damping_rate(par[P_XI])
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
def phase_before_grid(EMBED4, ftab, jn, u):
    """Sine and cosine of the closed-form forcing's phase the angle ``u`` (``omega`` times a
    time within a grid step, ``|u| <= 2 pi / N``) before the start of grid step ``jn`` of the
    period: the table's exact values rotated back, instead of a sine of ``omega t + phi`` (no
    library call, and no rounding of a large ``t``). Zero with the embedding, whose forcing is
    integrated."""
    if EMBED4 is not None:
        return 0.0, 0.0
    return harmonic.phase_before(ftab[jn, FT_SIN], ftab[jn, FT_COS], u)


@jit(nrt=False)
def forcing_at(t, par):
    """The closed-form forcing ``r`` at ``t`` (:func:`rockjit.plugs.harmonic.forcing_closed`)."""
    return harmonic.forcing_closed(t, par[P_OMEGA], par[P_PHI])


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
            fr[i] = aw2 * harmonic.advance(sp, cp, tab[T_ROTC, i], tab[T_ROTS, i])
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


# ---- the step of the transient kernel (:mod:`rockjit._engine.transient`) -----------------------
# the forcing of a cell is its excitation plug's value (rockjit.plugs), its instant given

@jit(nrt=False, inline=True)
def plug_forcing(t, fx, rec):
    """The base acceleration (``g``) of the forcing ``fx``
    (:func:`rockjit._engine.transient.forcing_of`) at model time ``t``: its plug's value
    (:func:`rockjit.plugs.plug_value`), zero outside ``[0, end]``."""
    end, code, a, off, n = fx
    if not (0.0 <= t <= end):
        return 0.0
    return plug_value(code, t, a, rec, off, n)


@jit(nrt=False, inline=True)
def plug_acc(th, v, t, side, sthc, cthc, xi, fx, rec):
    """``theta''`` on corner ``side`` at ``(t, th, v)``: :func:`rockjit.model.corner` and
    :func:`rockjit.model.accel_pq` (what :func:`rockjit.model.accel` computes, with the
    block's ``sin(thc), cos(thc)`` taken once)."""
    P, Q = corner(plug_forcing(t, fx, rec), side, sthc, cthc)
    s, c = sincos(th)
    return accel_pq(P, Q, s, c, v, xi)


@jit(nrt=False, inline=True)
def free_acc(th, v, side, sthc, cthc, xi):
    """``theta''`` on corner ``side`` with the base still (after the excitation)."""
    P, Q = corner(0.0, side, sthc, cthc)
    s, c = sincos(th)
    return accel_pq(P, Q, s, c, v, xi)


def _plug_stage(i):
    """Stage ``i``'s ``theta''``, its instant kept at or below ``cap``."""
    c = node(i)
    at = "t + hh" if c == "1.0" else f"t + {c} * hh"
    return f"k{i} = plug_acc(x{i}, v{i}, min({at}, cap), side, sthc, cthc, xi, fx, rec)"


dp_step = compile_step(
    "dp_step", "t, x0, v0, k0, hh, cap, side, sthc, cthc, xi, fx, rec",
    chain(_plug_stage, arith="plain", form="first", h="hh") + ["return x6, v6, k6"],
    globals(), jit(nrt=False, inline=True), doc="""One Dormand–Prince step of length ``hh``
    from ``(t, theta, theta')`` (``k0``: ``theta''`` there): ``(theta, theta', theta'')`` at
    ``t + hh``, the stage chain of :mod:`rockjit._engine.stages` in its first-order form with
    literal coefficients. The stages' instants are kept at or below ``cap``, the grid instant
    that ends the step: a step that ends on the excitation's end sees the forcing's value there
    even where ``t + hh`` rounds beyond it (the one-cosine pulse ends on ``a_p``).""")
