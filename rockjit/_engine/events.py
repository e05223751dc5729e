"""Events within a step: detection, the event functions, the event interpolant and its error,
and the root finders that locate an impact, an overturning or an uplift on the step's data
(:func:`locate_interp`) or along genuine steps (:func:`locate_step`); for the transient
kernel, the crests, dips, impacts and overturning inside a step, each located along genuine
steps of its own (:func:`locate_transient`).
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import fma, jit
from ..model import jerk_snap
from ..plugs.harmonic import curvature, oscillator
from .layout import (BISECT_ITERS, DELTA_EULER, EV_IMPACT, EV_NONE, EV_OVERTURN, EV_UPLIFT,
                     LOCATE_TOL, NEWTON_ITERS, OFF_GRID, O_RESTEP, O_RHS, O_UNCONVERGED, P_AW2,
                     P_COT, P_CTHC, P_OMEGA, P_STHC, P_THOVER, P_XI, ROOT_ITERS)
from .step import dense_coeffs, dp_step, rk_step
from .tableau import N_STAGES, P, step_table


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
    """The jerk and snap of theta (:func:`rockjit.model.jerk_snap`) at a point of a step on
    corner ``side``, under the closed-form forcing: ``f`` and its time derivative ``df`` there,
    and its second (:func:`rockjit.plugs.harmonic.curvature`)."""
    ddf = curvature(par[P_OMEGA], f)
    return jerk_snap(f, df, ddf, side, par[P_STHC], par[P_CTHC], par[P_XI], s, c, v, a)


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


@jit(ir_inline=True)
def event_poly(kind, side, par, tc):
    """The coefficients ``g0 .. g7`` of the event function ``g`` (positive before the event,
    :func:`event_g`) on theta's interpolant ``tc`` (:func:`interpolant`), as a polynomial in
    ``x = tau / hh``: ``sg theta + g_off`` (an impact or an overturning)."""
    sg = float(side) if kind == EV_IMPACT else -float(side)
    g0 = fma(sg, tc[0], par[P_THOVER] if kind == EV_OVERTURN else 0.0)
    g1 = sg * tc[1]
    g2 = sg * tc[2]
    g3 = sg * tc[3]
    g4 = sg * tc[4]
    g5 = sg * tc[5]
    g6 = sg * tc[6]
    g7 = sg * tc[7]
    return g0, g1, g2, g3, g4, g5, g6, g7


@jit(ir_inline=True)
def newton_start(g0, g1, g2, a, b, ga, gb):
    """Where Newton's iteration for the root of ``g`` in the bracket ``[a, b]`` (``g`` is ``ga
    > 0`` at ``a``, ``gb <= 0`` at ``b``) starts: the root in the bracket of the quadratic
    ``g0 + g1 x + g2 x^2`` (the step's start's Taylor polynomial: it finds the far root of a
    flight that starts on ``g = 0``), else regula falsi's, else the bracket's middle."""
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
    return x


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
    length is the more accurate (tests/_engine/test_integrate.py: the dips through 0 at N = 16).

    Returns ``(ok, x, theta, theta')``: ``x = tau / hh`` and the state there; ``ok`` is 1 when
    trusted, 0 when not (``x`` then starts the genuine steps' Newton iteration,
    :func:`locate_step`), -1 when the interpolant does not bracket the event as the step's
    data did.
    """
    tc, vc, cint, dfc = interpolant(y, ynew, hh, K, side, par, trig, f0, df0, f1, df1)
    g0, g1, g2, g3, g4, g5, g6, g7 = event_poly(kind, side, par, tc)
    # the coefficients of g's derivative
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
    # Newton from its start, stopped once its step is below 1e-9 (the next would be below
    # 1e-17: it converges quadratically); a step that leaves the bracket bisects it
    x = newton_start(g0, g1, g2, a, b, ga, gb)
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


# ---- the transient kernel's events (:mod:`rockjit._engine.transient`), along genuine steps ----

_EPS = float(np.finfo(float).eps)


@jit(nrt=False)
def locate_transient(kind, target, t, th, v, a0, lo, hi, glo, cap, side, sthc, cthc, xi, fx,
                     rec):
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
        th1, v1, a1 = dp_step(t, th, v, a0, z, cap, side, sthc, cthc, xi, fx, rec)
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
    th1, v1, a1 = dp_step(t, th, v, a0, z, cap, side, sthc, cthc, xi, fx, rec)
    return z, th1, v1, a1, steps


@jit(ir_inline=True)
def crest_in(t, th, v, a, hh, tn, v1, side, sthc, cthc, xi, fx, rec):
    """A maximum of ``side * theta`` inside the step (rising at its start, or about to: the
    instant of an uplift, and falling at its end): ``(found, its instant, theta and theta'
    there, the steps its location took)``; ``(False, 0, 0, 0, 0)`` if none."""
    if not ((side * v > 0.0 or (v == 0.0 and side * a > 0.0)) and side * v1 < 0.0):
        return False, 0.0, 0.0, 0.0, 0
    tau, th_c, vc, ac, ns = locate_transient(1, 0.0, t, th, v, a, 0.0, hh, 1.0, tn, side,
                                             sthc, cthc, xi, fx, rec)
    return True, tau, th_c, vc, ns


@jit(ir_inline=True)
def reach_in(kind, target, glo, t, th, v, a, lo, hi, tn, side, sthc, cthc, xi, fx, rec):
    """Where in the step ``side * theta`` reaches ``target`` (``kind`` 0) between ``lo`` and
    ``hi`` (:func:`locate_transient`; ``glo``, the event function's sign just after ``lo``):
    ``(the instant, theta and theta' there, the steps its location took)``."""
    tau, th2, v2, a2, ns = locate_transient(kind, target, t, th, v, a, lo, hi, glo, tn, side,
                                            sthc, cthc, xi, fx, rec)
    return tau, th2, v2, ns


@jit(ir_inline=True)
def impact_in(crest, t, th, v, a, hh, tn, th1, v1, side, sthc, cthc, xi, fx, rec):
    """Whether the step went through an impact: ``(where it ends, or -1, the steps its search
    took)``; the step's end if it ends beyond ``theta = 0``, else a dip's minimum
    (:func:`dip_in`) in a step without a crest."""
    if side * th1 < 0.0:
        return hh, 0
    if crest:
        return -1.0, 0
    return dip_in(t, th, v, a, hh, tn, v1, side, sthc, cthc, xi, fx, rec)


@jit(ir_inline=True)
def dip_in(t, th, v, a, hh, tn, v1, side, sthc, cthc, xi, fx, rec):
    """Where a step whose ``side * theta`` falls then rises (a minimum inside it) goes through
    an impact and back: ``(the minimum's instant if side * theta is negative there, else -1;
    the steps its location took)``."""
    if not (side * v < 0.0 and side * v1 > 0.0):
        return -1.0, 0
    tau, th2, v2, a2, ns = locate_transient(1, 0.0, t, th, v, a, 0.0, hh, side * v, tn, side,
                                            sthc, cthc, xi, fx, rec)
    return (tau if side * th2 < 0.0 else -1.0), ns
