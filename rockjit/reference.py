"""The scipy reference path: ``solve_ivp`` driven through the same model functions.

This is how the study computed its trajectories (docs/theory/integrator.md): ``solve_ivp`` (BDF, rtol 1e-6,
atol 1e-9) on the 4-D embedding, with terminal events at ``theta = 0`` and ``|theta| = theta_over``
and a restart after each impact. Any ``solve_ivp`` method and tolerance may be chosen; the rest and
overturning rules, the jump and the Zeno cut-off are those of the compiled path, and every
equation comes from :mod:`rockjit.model` (the forcing from :mod:`rockjit.plugs.harmonic`). It is
slow by design: it is the independent reference the compiled integrator is checked against.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from .model import Block, accel, accel_jac, initial_side, jump
from .plugs.harmonic import (forcing_closed, oscillator, oscillator_jac, peak_after, phase_at,
                             uplift_time)
from .result import Result

# A point just off theta = 0 on the new corner after an impact, so that the impact event of the
# next segment is not found again at its own starting instant.
_TINY = np.finfo(float).tiny


def _fields(block: Block, forcing, phi: float, embed4: bool):
    thc, xi, aw2, omega = block.thc, block.xi, forcing.alpha * forcing.omega**2, forcing.omega

    def forcing(t, z):
        return z[2] if embed4 else forcing_closed(t, omega, phi)

    def fun(t, z, side):
        r = forcing(t, z)
        out = np.empty(z.shape[0])
        out[0] = z[1]
        out[1] = accel(z[0], z[1], aw2 * r, side, thc, xi)
        if embed4:
            out[2], out[3] = oscillator(z[2], z[3], omega)
        return out

    def jac(t, z, side):
        r = forcing(t, z)
        ja, jb, jf = accel_jac(z[0], z[1], aw2 * r, side, thc, xi)
        n = z.shape[0]
        J = np.zeros((n, n))
        J[0, 1] = 1.0
        J[1, 0] = ja
        J[1, 1] = jb
        if embed4:
            J[1, 2] = aw2 * jf
            a, b, c, d = oscillator_jac(z[2], z[3], omega)
            J[2, 2], J[2, 3], J[3, 2], J[3, 3] = a, b, c, d
        return J

    return fun, jac, forcing


def simulate_scipy(p):
    """Reference run of a :class:`rockjit.single.RunPlan` through ``scipy.integrate.solve_ivp``
    (its method and tolerances in ``p.method``, a :class:`rockjit.Scipy`); returns a
    :class:`Result`.

    Samples are taken at the compiled path's grid points (``T/2`` for the stroboscopic
    sections, ``record_stride`` steps for the trajectory) from the solver's own output.
    """
    run = _ScipyRun(p)
    while run.status is None and run.t < run.t_end:
        if run.side == 0:
            if run.embed4:
                run.wait_embedded()
            else:
                run.wait_closed()
        elif run.fly():
            run.impact()
    return run.result()


class _Samples:
    """The run's states at the sample instants, by time, and the sections and the trajectory
    read off them."""

    def __init__(self, embed4, omega, phi, T):
        self.embed4, self.omega, self.phi, self.T = embed4, omega, phi, T
        self.by_time = {}

    def take(self, ts, ys):
        """Keep the states ``ys[:, k]`` at the times ``ts[k]``."""
        for tk, yk in zip(ts, ys.T):
            self.by_time[float(tk)] = yk

    def at_rest(self, ts, rs=None):
        """Keep the block at rest at the times ``ts`` (with the oscillator's ``rs[:, k]`` when
        it is integrated)."""
        for i, tk in enumerate(ts):
            if self.embed4:
                self.by_time[float(tk)] = np.array([0.0, 0.0, rs[0, i], rs[1, i]])
            else:
                self.by_time[float(tk)] = np.array([0.0, 0.0])

    def full(self, tk, yk):
        """The state ``(theta, theta', r, s)`` at ``tk`` (``r, s`` of the closed form)."""
        if self.embed4:
            return yk
        return np.array([yk[0], yk[1], *phase_at(tk, self.omega, self.phi)])

    def sections(self, t_half, periods, t):
        """The stroboscopic samples at ``t_half[0::2]`` and at ``t_half[1::2]``, in order, as
        far as the run went (to ``t``)."""
        T = self.T
        have = np.array(sorted(self.by_time))

        def near(tk):
            i = np.searchsorted(have, tk - 1e-9 * T)
            if i < len(have) and abs(have[i] - tk) <= 1e-9 * T:
                return self.full(tk, self.by_time[have[i]])
            return None

        strobe = [near(t_half[2 * k]) for k in range(periods + 1) if (k * T) <= t + 1e-9 * T]
        strobe_half = [near(t_half[2 * k + 1]) for k in range(periods)
                       if t_half[2 * k + 1] <= t]
        return [s for s in strobe if s is not None], [s for s in strobe_half if s is not None]

    def trajectory(self, dt):
        """``(t, theta, theta', r, s)`` at the samples on the grid of step ``dt``."""
        return np.array([[tk, *self.full(tk, self.by_time[tk])]
                         for tk in np.array(sorted(self.by_time))
                         if np.isclose(tk / dt, round(tk / dt), rtol=0, atol=1e-6)])


class _ScipyRun:
    """One reference run as it goes: the clock, the state on its corner (``side``; 0 at rest),
    the impacts and counters, and the samples; each method is one phase of the motion."""

    def __init__(self, p):
        self.p, self.block, self.forcing = p, p.block, p.forcing
        self.embed4 = self.forcing.embedded
        self.fun, self.jac, _ = _fields(self.block, self.forcing, p.phi, self.embed4)
        self.T = self.forcing.period
        self.h = self.T / p.n_steps
        self.t_end = p.periods * self.T
        self.aw2, self.cot, self.omega = (self.forcing.alpha * self.forcing.omega**2,
                                          self.block.cot, self.forcing.omega)
        self.thover, self.e = p.integration.theta_over, self.block.restitution
        self.solver = dict(method=p.method.method, rtol=p.method.rtol, atol=p.method.atol)
        # sample times: the half-period grid, and the trajectory grid if asked
        self.t_half = np.arange(2 * p.periods + 1) * (self.T / 2)
        self.t_samp = self.t_half
        if p.record_stride:
            t_traj = (np.arange(p.periods * p.n_steps // p.record_stride + 1)
                      * (self.h * p.record_stride))
            self.t_samp = np.union1d(self.t_half, t_traj)
        self.samples = _Samples(self.embed4, self.omega, p.phi, self.T)
        theta0, dtheta0, r0, s0 = p.y0
        self.z = np.array([theta0, dtheta0, r0, s0] if self.embed4 else [theta0, dtheta0],
                          dtype=float)
        self.side = initial_side(theta0, dtheta0)
        self.t = 0.0
        self.t_lift = -math.inf
        self.hold_until = -math.inf
        self.status = None
        self.impacts = []
        self.nfev = self.nsteps = self.n_rest = 0
        self.t_overturn = math.nan
        if self.side != 0 and self.side * self.z[0] >= self.thover:
            self.status = "overturned"
        self.samples.take([0.0], self.z[:, None])

    def ahead(self, t_stop):
        """The sample times after now, up to ``t_stop``."""
        return self.t_samp[(self.t_samp > self.t) & (self.t_samp <= t_stop)]

    def wait_embedded(self):
        """At rest with the oscillator integrated: wait for ``|f| > cot(thc)``."""
        aw2, cot, omega, z = self.aw2, self.cot, self.omega, self.z
        if aw2 * peak_after(math.hypot(z[2], z[3])) <= cot:
            self.status = "rest"
            return
        if aw2 * abs(z[2]) > cot:
            self.side = 1 if z[2] > 0 else -1
            z[0] = self.side * _TINY
            return

        def osc(tt, w):
            return np.array(oscillator(w[0], w[1], omega))

        def lift(tt, w):
            return (aw2 * w[0]) ** 2 - cot**2
        lift.terminal = True
        lift.direction = 1
        sol = solve_ivp(osc, (self.t, self.t_end), z[2:], events=lift,
                        t_eval=self.ahead(self.t_end), **self.solver)
        self.nfev += sol.nfev
        self.nsteps += len(sol.t)
        self.samples.at_rest(sol.t, np.asarray(sol.y).reshape(2, -1))
        if sol.status == 1:
            self.t = float(sol.t_events[0][0])
            self.z = np.array([0.0, 0.0, *sol.y_events[0][0]])
            self.side = 1 if self.z[2] > 0 else -1
            self.z[0] = self.side * _TINY
        else:
            self.t = self.t_end
            self.z = np.array([0.0, 0.0, *np.asarray(sol.y)[:, -1]])

    def wait_closed(self):
        """At rest under the closed form: wait for its uplift time."""
        # held at rest to the grid point after a flight too short to resolve (the compiled
        # path's rule: forcing a hair above the threshold would stall here)
        omega, phi = self.omega, self.p.phi
        t_up = uplift_time(max(self.t, self.hold_until), self.aw2, self.cot, omega, phi)
        if t_up == math.inf:
            self.status = "rest"
            return
        t_stop = min(t_up, self.t_end)
        self.samples.at_rest(self.ahead(t_stop))
        self.t = t_stop
        if t_up <= self.t_end:
            self.t_lift = self.t
            self.side = 1 if forcing_closed(self.t, omega, phi) > 0 else -1
            self.z = np.array([self.side * _TINY, 0.0])

    def flight_events(self):
        """The events of a flight on corner ``side``: impact, overturning, turning point."""
        side, thover = self.side, self.thover

        def impact(tt, zz, side=side):  # side comes again from solve_ivp's args
            return side * zz[0]
        impact.terminal = True
        impact.direction = -1

        def over(tt, zz, side=side, thover=thover):
            return thover - side * zz[0]
        # else noted and integrated through (the study's way)
        over.terminal = self.p.integration.stop_at_overturn
        over.direction = -1

        def turn(tt, zz, side=side):
            # the lowest point of side * theta: solve_ivp sees sign changes only between its
            # own steps, so a dip through theta = 0 and back within one step is found here
            return side * zz[1]
        turn.direction = 1
        return impact, over, turn

    def dip(self, sol, t_stop):
        """The first crossing of ``theta = 0`` before ``t_stop`` at a turning point below it
        (a dip through 0 and back between the solver's steps), or ``None``."""
        side, t_left = self.side, self.t
        for t_turn in sol.t_events[2]:
            if t_turn >= t_stop:
                break
            if t_turn > self.t and side * sol.sol(t_turn)[0] < 0.0:
                return brentq(lambda tt: side * sol.sol(tt)[0], t_left, t_turn,
                              xtol=4 * np.finfo(float).eps * max(1.0, abs(t_turn)))
            t_left = t_turn
        return None

    def fly(self):
        """In flight on corner ``side`` to the next impact, overturning or the end; returns
        whether it ends at an impact (the state just before it in ``z``)."""
        stop_at_overturn = self.p.integration.stop_at_overturn
        method = self.solver["method"]
        opts = {"jac": self.jac} if method in ("BDF", "Radau", "LSODA") else {}
        sol = solve_ivp(self.fun, (self.t, self.t_end), self.z, events=self.flight_events(),
                        t_eval=self.ahead(self.t_end), args=(self.side,), dense_output=True,
                        **self.solver, **opts)
        self.nfev += sol.nfev
        if sol.status == -1:
            self.status = "nonfinite"
            return False
        sol_t = np.asarray(sol.t, dtype=float)
        sol_y = np.asarray(sol.y, dtype=float).reshape(len(self.z), -1)
        n_term = 2 if stop_at_overturn else 1  # the terminal events
        t_stop = self.t_end if sol.status == 0 else min(
            (float(ev[0]) for ev in sol.t_events[:n_term] if len(ev)), default=self.t_end)
        dip = self.dip(sol, t_stop)
        t_cut = dip if dip is not None else t_stop
        keep = sol_t <= t_cut
        if not stop_at_overturn and len(sol.t_events[1]) and sol.t_events[1][0] <= t_cut:
            self.t_overturn = float(sol.t_events[1][0])
            self.thover = math.inf  # noted once, as the compiled path does
        self.nsteps += int(np.count_nonzero(keep))
        self.samples.take(sol_t[keep], sol_y[:, keep])
        return self.land(sol, sol_y, dip, stop_at_overturn)

    def land(self, sol, sol_y, dip, stop_at_overturn):
        """Where a flight ended: at a dip or an impact (``True``), at the end of the run or
        overturned."""
        if dip is not None:
            self.t = float(dip)
            self.z = sol.sol(self.t).copy()
            self.z[0] = 0.0
            return True
        if sol.status == 0:
            self.t = self.t_end
            # the last sample point is t_end itself (t_half ends there)
            self.z = sol_y[:, -1]
            return False
        t_ev = sol.t_events
        if stop_at_overturn and len(t_ev[1]) and (not len(t_ev[0]) or t_ev[1][0] <= t_ev[0][0]):
            self.t = float(t_ev[1][0])
            self.z = sol.y_events[1][0].copy()
            self.status = "overturned"
            return False
        self.t = float(t_ev[0][0])
        self.z = sol.y_events[0][0].copy()
        return True

    def impact(self):
        """The jump at ``theta = 0`` onto the other corner, or to rest below the Zeno
        cut-off."""
        z, t = self.z, self.t
        dth_m = z[1]
        dth_p = jump(dth_m, self.block.rule.at_impact(abs(dth_m), self.e))
        self.impacts.append((t, dth_m, dth_p))
        self.side = -self.side
        z[0] = self.side * _TINY
        z[1] = dth_p
        if abs(dth_p) < self.p.integration.rest_speed or dth_p == 0.0:
            z[0] = 0.0
            z[1] = 0.0
            self.side = 0
            self.n_rest += 1
            if t - self.t_lift <= 1e-9 * self.h:
                self.hold_until = (math.floor(t / self.h) + 1) * self.h
        if len(self.impacts) >= self.p.max_impacts:
            self.status = "max_impacts"

    def result(self):
        """The run as a :class:`Result`."""
        p, t = self.p, self.t
        status = "done" if self.status is None else self.status
        state = np.array(self.samples.full(t, self.z), dtype=float)
        strobe, strobe_half = self.samples.sections(self.t_half, p.periods, t)
        traj = self.samples.trajectory(self.h * p.record_stride) if p.record_stride else None
        return Result(
            block=self.block, forcing=self.forcing, integration=p.integration,
            method=f"scipy:{self.solver['method']}", status=status, t=float(t), state=state,
            period=self.T, n_steps=p.n_steps, periods=p.periods,
            strobe=np.array(strobe).reshape(-1, 4),
            strobe_half=np.array(strobe_half).reshape(-1, 4),
            impacts=np.array(self.impacts).reshape(-1, 3), n_impacts=len(self.impacts),
            n_grid_steps=self.nsteps, n_rhs=self.nfev, max_error_estimate=math.nan,
            trajectory=traj, n_rest=self.n_rest, t_overturn=self.t_overturn,
        )
