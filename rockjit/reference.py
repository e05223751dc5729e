"""The scipy reference path: ``solve_ivp`` driven through the same model functions.

This is how the study computed its trajectories (docs/theory/integrator.md): ``solve_ivp`` (BDF, rtol 1e-6,
atol 1e-9) on the 4-D embedding, with terminal events at ``theta = 0`` and ``|theta| = theta_over``
and a restart after each impact. Any ``solve_ivp`` method and tolerance may be chosen; the rest and
overturning rules, the jump and the Zeno cut-off are those of the compiled path, and every
equation comes from :mod:`rockjit.model`. It is slow by design: it is the independent reference
the compiled integrator is checked against.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from .model import (Block, accel, accel_jac, forcing_closed, initial_side, jump, oscillator,
                    oscillator_jac, uplift_time)
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
    block, forcing, phi, n_steps = p.block, p.forcing, p.phi, p.n_steps
    theta0, dtheta0, r0, s0 = p.y0
    periods, record_stride, max_impacts = p.periods, p.record_stride, p.max_impacts
    ivp_method, rtol, atol = p.method.method, p.method.rtol, p.method.atol
    stop_at_overturn = p.integration.stop_at_overturn
    embed4 = forcing.embedded
    fun, jac, forc = _fields(block, forcing, phi, embed4)
    T = forcing.period
    h = T / n_steps
    t_end = periods * T
    aw2, cot, omega, thover, e = (forcing.alpha * forcing.omega**2, block.cot, forcing.omega,
                                  p.integration.theta_over, block.restitution)
    # sample times: the half-period grid, and the trajectory grid if asked
    t_half = np.arange(2 * periods + 1) * (T / 2)
    t_samp = t_half
    if record_stride:
        t_traj = np.arange(periods * n_steps // record_stride + 1) * (h * record_stride)
        t_samp = np.union1d(t_half, t_traj)
    samples = {}

    def take(ts, ys):
        for tk, yk in zip(ts, ys.T):
            samples[float(tk)] = yk

    def rest_sample(ts, rs=None):
        for i, tk in enumerate(ts):
            if embed4:
                samples[float(tk)] = np.array([0.0, 0.0, rs[0, i], rs[1, i]])
            else:
                samples[float(tk)] = np.array([0.0, 0.0])

    z = np.array([theta0, dtheta0, r0, s0] if embed4 else [theta0, dtheta0], dtype=float)
    side = initial_side(theta0, dtheta0)
    t = 0.0
    t_lift = -math.inf
    hold_until = -math.inf
    status = None
    impacts = []
    nfev = 0
    nsteps = 0
    n_rest = 0
    t_overturn = math.nan
    if side != 0 and side * z[0] >= thover:
        status = "overturned"
    take([0.0], z[:, None])

    while status is None and t < t_end:
        if side == 0:
            # ---- at rest: wait for |f| > cot(thc) -----------------------------------------
            if embed4:
                rad = math.hypot(z[2], z[3])
                if aw2 * max(1.0, rad) <= cot:
                    status = "rest"
                    break
                if aw2 * abs(z[2]) > cot:
                    side = 1 if z[2] > 0 else -1
                    z[0] = side * _TINY
                    continue

                def osc(tt, w):
                    return np.array(oscillator(w[0], w[1], omega))

                def lift(tt, w):
                    return (aw2 * w[0]) ** 2 - cot**2
                lift.terminal = True
                lift.direction = 1
                ts = t_samp[(t_samp > t) & (t_samp <= t_end)]
                sol = solve_ivp(osc, (t, t_end), z[2:], method=ivp_method, rtol=rtol,
                                atol=atol, events=lift, t_eval=ts)
                nfev += sol.nfev
                nsteps += len(sol.t)
                rest_sample(sol.t, np.asarray(sol.y).reshape(2, -1))
                if sol.status == 1:
                    t = float(sol.t_events[0][0])
                    z = np.array([0.0, 0.0, *sol.y_events[0][0]])
                    side = 1 if z[2] > 0 else -1
                    z[0] = side * _TINY
                else:
                    t = t_end
                    z = np.array([0.0, 0.0, *np.asarray(sol.y)[:, -1]])
            else:
                # held at rest to the grid point after a flight too short to resolve (the
                # compiled path's rule: forcing a hair above the threshold would stall here)
                t_up = uplift_time(max(t, hold_until), aw2, cot, omega, phi)
                if t_up == math.inf:
                    status = "rest"
                    break
                t_stop = min(t_up, t_end)
                ts = t_samp[(t_samp > t) & (t_samp <= t_stop)]
                rest_sample(ts)
                t = t_stop
                if t_up <= t_end:
                    t_lift = t
                    side = 1 if forcing_closed(t, omega, phi) > 0 else -1
                    z = np.array([side * _TINY, 0.0])
            continue

        # ---- in flight on corner `side` ------------------------------------------------------
        def impact(tt, zz, side=side):
            return side * zz[0]
        impact.terminal = True
        impact.direction = -1

        def over(tt, zz, side=side, thover=thover):
            return thover - side * zz[0]
        over.terminal = stop_at_overturn  # else noted and integrated through (the study's way)
        over.direction = -1

        def turn(tt, zz, side=side):
            # the lowest point of side * theta: solve_ivp sees sign changes only between its
            # own steps, so a dip through theta = 0 and back within one step is found here
            return side * zz[1]
        turn.direction = 1

        ts = t_samp[(t_samp > t) & (t_samp <= t_end)]
        opts = {"jac": jac} if ivp_method in ("BDF", "Radau", "LSODA") else {}
        sol = solve_ivp(fun, (t, t_end), z, method=ivp_method, rtol=rtol, atol=atol,
                        events=(impact, over, turn), t_eval=ts, args=(side,),
                        dense_output=True, **opts)
        nfev += sol.nfev
        if sol.status == -1:
            status = "nonfinite"
            break
        sol_t = np.asarray(sol.t, dtype=float)
        sol_y = np.asarray(sol.y, dtype=float).reshape(len(z), -1)
        n_term = 2 if stop_at_overturn else 1  # the terminal events
        t_stop = t_end if sol.status == 0 else min(
            (float(ev[0]) for ev in sol.t_events[:n_term] if len(ev)), default=t_end)
        dip = None
        t_left = t
        for t_turn in sol.t_events[2]:
            if t_turn >= t_stop:
                break
            if t_turn > t and side * sol.sol(t_turn)[0] < 0.0:
                dip = brentq(lambda tt: side * sol.sol(tt)[0], t_left, t_turn,
                             xtol=4 * np.finfo(float).eps * max(1.0, abs(t_turn)))
                break
            t_left = t_turn
        keep = sol_t <= (dip if dip is not None else t_stop)
        if not stop_at_overturn and len(sol.t_events[1]) and \
                sol.t_events[1][0] <= (dip if dip is not None else t_stop):
            t_overturn = float(sol.t_events[1][0])
            thover = math.inf  # noted once, as the compiled path does
        nsteps += int(np.count_nonzero(keep))
        take(sol_t[keep], sol_y[:, keep])
        if dip is not None:
            t = float(dip)
            z = sol.sol(t).copy()
            z[0] = 0.0
        elif sol.status == 0:
            t = t_end
            # the last sample point is t_end itself (t_half ends there)
            z = sol_y[:, -1]
            break
        elif stop_at_overturn and len(sol.t_events[1]) and (
                not len(sol.t_events[0]) or sol.t_events[1][0] <= sol.t_events[0][0]):
            t = float(sol.t_events[1][0])
            z = sol.y_events[1][0].copy()
            status = "overturned"
            break
        else:
            t = float(sol.t_events[0][0])
            z = sol.y_events[0][0].copy()
        dth_m = z[1]
        dth_p = jump(dth_m, block.rule.at_impact(abs(dth_m), e))
        impacts.append((t, dth_m, dth_p))
        side = -side
        z[0] = side * _TINY
        z[1] = dth_p
        if abs(dth_p) < p.integration.rest_speed or dth_p == 0.0:
            z[0] = 0.0
            z[1] = 0.0
            side = 0
            n_rest += 1
            if t - t_lift <= 1e-9 * h:
                hold_until = (math.floor(t / h) + 1) * h
        if len(impacts) >= max_impacts:
            status = "max_impacts"
            break

    if status is None:
        status = "done"
    # final state with (r, s)
    if embed4:
        state = np.array(z, dtype=float)
    else:
        psi = omega * t + phi
        state = np.array([z[0], z[1], math.sin(psi), math.cos(psi)])

    def full(tk, yk):
        if embed4:
            return yk
        psi = omega * tk + phi
        return np.array([yk[0], yk[1], math.sin(psi), math.cos(psi)])

    have = np.array(sorted(samples))
    # stroboscopic samples in order, only as far as the run went
    k_full = [k for k in range(periods + 1) if (k * T) <= t + 1e-9 * T]
    strobe = []
    for k in range(len(k_full)):
        tk = t_half[2 * k]
        i = np.searchsorted(have, tk - 1e-9 * T)
        if i < len(have) and abs(have[i] - tk) <= 1e-9 * T:
            strobe.append(full(tk, samples[have[i]]))
    strobe_half = []
    for k in range(periods):
        tk = t_half[2 * k + 1]
        if tk > t:
            break
        i = np.searchsorted(have, tk - 1e-9 * T)
        if i < len(have) and abs(have[i] - tk) <= 1e-9 * T:
            strobe_half.append(full(tk, samples[have[i]]))
    traj = None
    if record_stride:
        traj = np.array([[tk, *full(tk, samples[tk])] for tk in have
                         if np.isclose(tk / (h * record_stride),
                                       round(tk / (h * record_stride)), rtol=0, atol=1e-6)])
    return Result(
        block=block, forcing=forcing, integration=p.integration, method=f"scipy:{ivp_method}",
        status=status, t=float(t), state=state,
        period=T, n_steps=n_steps, periods=periods,
        strobe=np.array(strobe).reshape(-1, 4), strobe_half=np.array(strobe_half).reshape(-1, 4),
        impacts=np.array(impacts).reshape(-1, 3), n_impacts=len(impacts),
        n_grid_steps=nsteps, n_rhs=nfev, max_error_estimate=math.nan, trajectory=traj,
        n_rest=n_rest, t_overturn=t_overturn,
    )
