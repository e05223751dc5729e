"""The scipy reference path for transient excitations: one run under a pulse or a record.

``scipy.integrate.solve_ivp`` integrates the block between events, with every equation taken
from :mod:`rockjit.model` (``accel``, ``accel_jac``, ``jump``), as the harmonic reference path
(:mod:`rockjit.reference`) does. The run is a sequence of phases:

- **rest**: the block waits for the first instant after which ``|f| > cot(thc)``; the
  excitation's ``windows`` give it exactly (in closed form for the sine and cosine pulses, to
  rounding for the Ricker wavelet's lobes, on its linear piece for a record). The block then
  leaves rest on the corner ``sign f``, from the first representable instant at which
  ``accel`` on that corner is strictly outward. A rest phase after the excitation ends is
  rest for good.
- **flight** on one corner, up to the next terminal event: an impact (``theta = 0``),
  overturning (``|theta| = theta_over``), the end of the excitation (``f`` jumps or kinks
  there, so the solver restarts on it) or the time limit. Non-terminal events mark the
  extremes of ``|theta|``: the maxima give ``max |theta|`` exactly, the minima catch a dip
  through ``theta = 0`` and back within one solver step, located by ``brentq`` on the dense
  output. The solver also restarts on every instant where ``f`` or its slope jumps (the
  excitation's ``breaks``: a pulse's end, every sample of a record), so that each of its steps
  sees a smooth ``f``: for a record this is both more accurate and about five times faster
  than letting the error control resolve each kink (measured on a FEMA P695 record: impact
  times within 3e-8 of each other at ``rtol`` 1e-8 and 1e-10, against 1e-6 and 7 times the
  right-hand-side evaluations without the restarts).
- **impact**: ``theta'+ = e theta'-`` on the other corner, or rest when ``|theta'+|`` is below
  the Zeno cut-off ``rest_speed``.

After the excitation, with ``stop_when_decided``, the run stops at the first instant the block
is at rest, or at the first start of a flight (the excitation's end, an impact) or crest from
which free rocking can neither overturn nor swing wider than the largest ``|theta|`` so far:
its energy, which free rocking only loses, is below the energy it takes to reach the tipping
angle ``alpha_s`` and at most the potential energy at that largest ``|theta|``
(:func:`rockjit.model.free_rocking_decided`; docs/guide/earthquakes.md).
"""

from __future__ import annotations

import bisect
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from ..model import accel, accel_jac, free_rocking_decided, initial_side, jump
from .response import TransientResult, alpha_s

__all__ = ["run_scipy"]

# a point just off theta = 0 on the new corner after an impact or an uplift, so that the
# impact event of the next flight is not found again at its starting instant
_TINY = np.finfo(float).tiny
_IMPLICIT = ("BDF", "Radau", "LSODA")


def run_scipy(block, excitation, state, settings, method) -> TransientResult:
    """One run of ``block`` under the bound transient ``excitation`` from ``state``
    (``(theta0, theta0')``) with the :class:`rockjit.ground.Transient` ``settings`` on the
    :class:`rockjit.Scipy` ``method``."""
    thc, xi, e, cot = block.thc, block.xi, block.restitution, block.cot
    f = excitation.scalar()
    end = float(excitation.end)
    t_lim = float(settings.limit(end))
    thover = settings.theta_over
    th_top = min(alpha_s(block.hb), thover)  # the tipping angle, or overturning before it

    def settled(theta, dtheta):
        """Free rocking from here can neither overturn nor swing wider than max|theta| so far."""
        return free_rocking_decided(float(theta), float(dtheta), float(max_th), thc, th_top)
    decide = settings.stop_when_decided
    keep_traj = settings.record
    rest_speed = settings.rest_speed
    max_impacts = settings.impact_bound()
    ivp, rtol, atol = method.method, method.rtol, method.atol
    max_step = excitation.max_step
    breaks = [float(b) for b in excitation.breaks if b > 0.0]
    windows = excitation.windows(cot)
    w_ends = windows[:, 1].tolist()

    def rhs(t, z, side):
        return np.array((z[1], accel(z[0], z[1], f(t), side, thc, xi)))

    def jac(t, z, side):
        ja, jb, _ = accel_jac(z[0], z[1], f(t), side, thc, xi)
        return np.array(((0.0, 1.0), (ja, jb)))

    opts = {"jac": jac} if ivp in _IMPLICIT else {}

    def next_uplift(t):
        """``(t_up, side)``: the first instant ``>= t`` at which the block at rest accelerates
        away from rest, or None."""
        k = bisect.bisect_right(w_ends, t)
        while k < len(w_ends):
            t0, t1, sg = windows[k]
            side = int(sg)
            tt = max(t, t0)
            step = 0.0
            while tt <= t1:
                if side * accel(side * _TINY, 0.0, f(tt), side, thc, xi) > 0.0:
                    return tt, side
                step = max(2.0 * step, math.ulp(max(tt, 1.0)))
                tt = max(t, t0) + step
            k += 1
        return None

    theta0, dtheta0 = state
    z = np.array([theta0, dtheta0], dtype=float)
    side = initial_side(theta0, dtheta0)
    t = 0.0
    status = None
    impacts = []
    traj = [(0.0, z[0], z[1])] if keep_traj else None
    max_th = abs(theta0)
    t_uplift = math.nan
    t_over = math.nan
    nfev = 0
    n_rest = 0

    while status is None:
        if t >= t_lim:
            status = "time_limit"
            break
        if side == 0:  # ---- at rest ----------------------------------------------------------
            up = next_uplift(t)
            if up is None:
                status = "rest"
                break
            if up[0] >= t_lim:
                if keep_traj:
                    traj.append((t_lim, 0.0, 0.0))
                t = t_lim
                status = "time_limit"
                break
            t_up, side = up
            if keep_traj and t_up > t:
                traj.append((t_up, 0.0, 0.0))
            t = t_up
            if math.isnan(t_uplift):
                t_uplift = t
            z = np.array([side * _TINY, 0.0])
            continue

        free = t >= end
        if free and decide and settled(z[0], z[1]):
            status = "decided"
            break
        if free:
            seg_end = t_lim
        else:  # the solver restarts on every break of f (every sample of a record)
            k = bisect.bisect_right(breaks, t)
            seg_end = min(t_lim, breaks[k] if k < len(breaks) else end)

        # ---- in flight on corner `side` ------------------------------------------------------
        def impact(tt, zz, side):
            return side * zz[0]
        impact.terminal = True
        impact.direction = -1

        def over(tt, zz, side):
            return thover - side * zz[0]
        over.terminal = True
        over.direction = -1

        def trough(tt, zz, side):  # a minimum of side * theta (a dip through 0 and back)
            return side * zz[1]
        trough.direction = 1

        def crest(tt, zz, side):  # a maximum of side * theta
            return side * zz[1]
        crest.direction = -1

        sol = solve_ivp(rhs, (t, seg_end), z, method=ivp, rtol=rtol, atol=atol,
                        events=(impact, over, trough, crest), args=(side,),
                        dense_output=True, max_step=max_step if not free else math.inf,
                        **opts)
        nfev += sol.nfev
        if sol.status == -1 or not np.all(np.isfinite(sol.y)):
            status = "nonfinite"
            break
        t_stop = seg_end if sol.status == 0 else min(
            float(ev[0]) for ev in sol.t_events[:2] if len(ev))
        # a dip through theta = 0 and back inside one step: the first trough below 0
        dip = None
        t_left = t
        for t_tr in sol.t_events[2]:
            if t_tr >= t_stop:
                break
            if t_tr > t and side * sol.sol(t_tr)[0] < 0.0:
                dip = brentq(lambda tt: side * sol.sol(tt)[0], t_left, t_tr,
                             xtol=4 * np.finfo(float).eps * max(1.0, abs(t_tr)))
                break
            t_left = t_tr
        stop = dip if dip is not None else t_stop
        # after the excitation, the first crest decides the run when it is below the top
        decided_at = None
        for t_cr, y_cr in zip(sol.t_events[3], sol.y_events[3]):
            if t_cr > stop:
                break
            max_th = max(max_th, abs(float(y_cr[0])))
            if decide and t_cr >= end and settled(y_cr[0], 0.0):
                decided_at = (float(t_cr), np.array(y_cr, dtype=float))
                stop = decided_at[0]
                break
        keep = sol.t <= stop
        if keep.any():
            max_th = max(max_th, float(np.max(np.abs(sol.y[0, keep]))))
        if keep_traj:
            traj.extend(zip(sol.t[keep][1:].tolist(), sol.y[0, keep][1:].tolist(),
                            sol.y[1, keep][1:].tolist()))
        if decided_at is not None:
            t, z = decided_at
            if keep_traj:
                traj.append((t, z[0], z[1]))
            status = "decided"
            break
        if dip is not None:
            t = float(dip)
            z = sol.sol(t).copy()
            z[0] = 0.0
        elif sol.status == 0:
            t = seg_end
            z = sol.y[:, -1].copy()
            continue  # the excitation's end (or the limit, ended at the loop's top)
        elif len(sol.t_events[1]) and (not len(sol.t_events[0])
                                       or sol.t_events[1][0] <= sol.t_events[0][0]):
            t = t_over = float(sol.t_events[1][0])
            z = sol.y_events[1][0].copy()
            max_th = max(max_th, thover)
            if keep_traj:
                traj.append((t, z[0], z[1]))
            status = "overturned"
            break
        else:
            t = float(sol.t_events[0][0])
            z = sol.y_events[0][0].copy()
        # ---- impact ----------------------------------------------------------------------------
        if keep_traj:
            traj.append((t, 0.0, z[1]))
        dth_m = float(z[1])
        dth_p = jump(dth_m, block.rule.at_impact(abs(dth_m), e))
        impacts.append((t, dth_m, dth_p))
        side = -side
        z = np.array([side * _TINY, dth_p])
        if abs(dth_p) < rest_speed or dth_p == 0.0:
            z[:] = 0.0
            side = 0
            n_rest += 1
        if len(impacts) >= max_impacts:
            status = "max_impacts"
            break

    trajectory = None
    if keep_traj:
        trajectory = np.array(traj, dtype=float).reshape(-1, 3)
    return TransientResult(
        block=block, excitation=excitation, settings=settings, method=method.name,
        status=status, t=float(t), state=np.array([z[0], z[1]], dtype=float),
        t_uplift=t_uplift, max_theta=float(max_th),
        impacts=np.array(impacts, dtype=float).reshape(-1, 3), t_overturn=t_over,
        trajectory=trajectory, n_rhs=int(nfev), n_rest=n_rest)
