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
    :class:`rockjit.Scipy` ``method``: rest, flight and impact in turn, until a status."""
    run = _TransientRun(block, excitation, state, settings, method)
    while run.status is None:
        if run.t >= run.t_lim:
            run.status = "time_limit"
        elif run.side == 0:
            run.wait()
        elif run.decided():
            run.status = "decided"
        elif run.fly():
            run.impact()
    return run.result()


def _flight_events(thover):
    """The events of a flight on the corner ``side`` (``solve_ivp``'s argument): impact
    (``theta = 0``) and overturning (``|theta| = thover``), terminal; the troughs and the crests
    of ``side * theta``."""
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
    return impact, over, trough, crest


class _TransientRun:
    """One reference run as it goes: the clock, the state on its corner (``side``; 0 at rest),
    the largest ``|theta|``, the impacts and the trajectory; each method is one phase of the
    motion."""

    def __init__(self, block, excitation, state, settings, method):
        self.block, self.excitation, self.settings, self.method = (block, excitation,
                                                                   settings, method)
        self.thc, self.xi, self.cot = block.thc, block.xi, block.cot
        self.f = excitation.scalar()
        self.end = float(excitation.end)
        self.t_lim = float(settings.limit(self.end))
        self.thover = settings.theta_over
        self.th_top = min(alpha_s(block.hb), self.thover)  # tipping, or overturning before it
        self.max_impacts = settings.impact_bound()
        self.solver = dict(method=method.method, rtol=method.rtol, atol=method.atol)
        if method.method in _IMPLICIT:
            self.solver["jac"] = self.jac
        self.events = _flight_events(self.thover)
        self.breaks = [float(b) for b in excitation.breaks if b > 0.0]
        self.windows = excitation.windows(self.cot)
        self.w_ends = self.windows[:, 1].tolist()
        theta0, dtheta0 = state
        self.z = np.array([theta0, dtheta0], dtype=float)
        self.side = initial_side(theta0, dtheta0)
        self.t = 0.0
        self.status = None
        self.impacts = []
        self.traj = [(0.0, self.z[0], self.z[1])] if settings.record else None
        self.max_th = abs(theta0)
        self.t_uplift = self.t_over = math.nan
        self.nfev = self.n_rest = 0

    def rhs(self, t, z, side):
        """The block's field on the corner ``side``."""
        return np.array((z[1], accel(z[0], z[1], self.f(t), side, self.thc, self.xi)))

    def jac(self, t, z, side):
        """The field's Jacobian, for the implicit methods."""
        ja, jb, _ = accel_jac(z[0], z[1], self.f(t), side, self.thc, self.xi)
        return np.array(((0.0, 1.0), (ja, jb)))

    def note(self, t, theta, dtheta):
        """Add ``(t, theta, theta')`` to the trajectory, when it is kept."""
        if self.traj is not None:
            self.traj.append((t, theta, dtheta))

    def settled(self, theta, dtheta):
        """Free rocking from here can neither overturn nor swing wider than max|theta| so far."""
        return free_rocking_decided(float(theta), float(dtheta), float(self.max_th), self.thc,
                                    self.th_top)

    def decided(self):
        """After the excitation, with ``stop_when_decided``: the state now decides the run."""
        return (self.t >= self.end and self.settings.stop_when_decided
                and self.settled(self.z[0], self.z[1]))

    def next_uplift(self, t):
        """``(t_up, side)``: the first instant ``>= t`` at which the block at rest accelerates
        away from rest, or None."""
        thc, xi, f = self.thc, self.xi, self.f
        k = bisect.bisect_right(self.w_ends, t)
        while k < len(self.w_ends):
            t0, t1, sg = self.windows[k]
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

    def wait(self):
        """At rest: to the next uplift, or to rest for good, or to the time limit."""
        up = self.next_uplift(self.t)
        if up is None:
            self.status = "rest"
            return
        t_up, side = up
        if t_up >= self.t_lim:
            self.note(self.t_lim, 0.0, 0.0)
            self.t = self.t_lim
            self.status = "time_limit"
            return
        if t_up > self.t:
            self.note(t_up, 0.0, 0.0)
        self.t, self.side = t_up, side
        if math.isnan(self.t_uplift):
            self.t_uplift = self.t
        self.z = np.array([side * _TINY, 0.0])

    def segment_end(self, free):
        """Where this flight's solver stops at the latest: the time limit after the
        excitation, else its next break (every sample of a record) or its end."""
        if free:
            return self.t_lim
        k = bisect.bisect_right(self.breaks, self.t)
        return min(self.t_lim, self.breaks[k] if k < len(self.breaks) else self.end)

    def fly(self):
        """In flight on corner ``side`` to the next event; returns whether it ends at an impact
        (the state just before it in ``z``)."""
        free = self.t >= self.end
        seg_end = self.segment_end(free)
        sol = solve_ivp(self.rhs, (self.t, seg_end), self.z, events=self.events,
                        args=(self.side,), dense_output=True,
                        max_step=self.excitation.max_step if not free else math.inf,
                        **self.solver)
        self.nfev += sol.nfev
        if sol.status == -1 or not np.all(np.isfinite(sol.y)):
            self.status = "nonfinite"
            return False
        t_stop = seg_end if sol.status == 0 else min(
            float(ev[0]) for ev in sol.t_events[:2] if len(ev))
        dip = self.dip(sol, t_stop)
        decided_at = self.crests(sol, dip if dip is not None else t_stop)
        if decided_at is not None:
            self.keep(sol, decided_at[0])
            self.t, self.z = decided_at
            self.note(self.t, self.z[0], self.z[1])
            self.status = "decided"
            return False
        self.keep(sol, dip if dip is not None else t_stop)
        return self.land(sol, seg_end, dip)

    def dip(self, sol, t_stop):
        """The first crossing of ``theta = 0`` before ``t_stop`` at a trough below it (a dip
        through 0 and back inside one solver step), or None."""
        side, t_left = self.side, self.t
        for t_tr in sol.t_events[2]:
            if t_tr >= t_stop:
                break
            if t_tr > self.t and side * sol.sol(t_tr)[0] < 0.0:
                return brentq(lambda tt: side * sol.sol(tt)[0], t_left, t_tr,
                              xtol=4 * np.finfo(float).eps * max(1.0, abs(t_tr)))
            t_left = t_tr
        return None

    def crests(self, sol, stop):
        """Raise ``max |theta|`` by the crests up to ``stop``; after the excitation, the first
        crest from which the run is decided, as ``(t, z)``, or None."""
        for t_cr, y_cr in zip(sol.t_events[3], sol.y_events[3]):
            if t_cr > stop:
                break
            self.max_th = max(self.max_th, abs(float(y_cr[0])))
            if self.settings.stop_when_decided and t_cr >= self.end \
                    and self.settled(y_cr[0], 0.0):
                return float(t_cr), np.array(y_cr, dtype=float)
        return None

    def keep(self, sol, stop):
        """Take the solver's points up to ``stop`` into ``max |theta|`` and the trajectory."""
        keep = sol.t <= stop
        if keep.any():
            self.max_th = max(self.max_th, float(np.max(np.abs(sol.y[0, keep]))))
        if self.traj is not None:
            self.traj.extend(zip(sol.t[keep][1:].tolist(), sol.y[0, keep][1:].tolist(),
                                 sol.y[1, keep][1:].tolist()))

    def land(self, sol, seg_end, dip):
        """Where a flight ended: at a dip or an impact (``True``), at the segment's end (the
        excitation's end or a break, or the limit, ended by the run's loop) or overturned."""
        if dip is not None:
            self.t = float(dip)
            self.z = sol.sol(self.t).copy()
            self.z[0] = 0.0
            return True
        if sol.status == 0:
            self.t = seg_end
            self.z = sol.y[:, -1].copy()
            return False
        t_ev = sol.t_events
        if len(t_ev[1]) and (not len(t_ev[0]) or t_ev[1][0] <= t_ev[0][0]):
            self.t = self.t_over = float(t_ev[1][0])
            self.z = sol.y_events[1][0].copy()
            self.max_th = max(self.max_th, self.thover)
            self.note(self.t, self.z[0], self.z[1])
            self.status = "overturned"
            return False
        self.t = float(t_ev[0][0])
        self.z = sol.y_events[0][0].copy()
        return True

    def impact(self):
        """The jump at ``theta = 0`` onto the other corner, or to rest below the Zeno
        cut-off; the run ends at the impact bound."""
        self.note(self.t, 0.0, self.z[1])
        dth_m = float(self.z[1])
        dth_p = jump(dth_m, self.block.rule.at_impact(abs(dth_m), self.block.restitution))
        self.impacts.append((self.t, dth_m, dth_p))
        self.side = -self.side
        self.z = np.array([self.side * _TINY, dth_p])
        if abs(dth_p) < self.settings.rest_speed or dth_p == 0.0:
            self.z[:] = 0.0
            self.side = 0
            self.n_rest += 1
        if len(self.impacts) >= self.max_impacts:
            self.status = "max_impacts"

    def result(self) -> TransientResult:
        """The run as a :class:`TransientResult`."""
        trajectory = None
        if self.traj is not None:
            trajectory = np.array(self.traj, dtype=float).reshape(-1, 3)
        z = self.z
        return TransientResult(
            block=self.block, excitation=self.excitation, settings=self.settings,
            method=self.method.name, status=self.status, t=float(self.t),
            state=np.array([z[0], z[1]], dtype=float), t_uplift=self.t_uplift,
            max_theta=float(self.max_th),
            impacts=np.array(self.impacts, dtype=float).reshape(-1, 3),
            t_overturn=self.t_over, trajectory=trajectory, n_rhs=int(self.nfev),
            n_rest=self.n_rest)
