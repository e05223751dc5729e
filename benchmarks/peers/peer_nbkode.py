"""numbakit-ode (nbkode) peer: nbkode's RK45 / DOP853 stepper inside a numba impact loop.

What a user competent in nbkode and numba writes: the rocking block's right-hand side as an
``njit`` function (the block's constants frozen into it by a closure, as nbkode's own ``params``
does); the state ``y = (theta, theta', side)`` with the corner ``side`` a constant of the flow
(``side' = 0``), so the stepper needs no other argument; nbkode's adaptive step
(``RungeKutta45._step`` / ``DOP853._step``: the step, its embedded error estimate, the step-size
controller, the FSAL push into its ``AlignedBuffer``) called from an ``njit`` loop that after each
accepted step looks for a sign change of ``theta`` (impact) or of ``theta_over - |theta|``
(overturning), locates it on nbkode's own dense output (its ``RkInterpolator`` /
``DOP853Interpolator``) by a bracketing root search (bisection with false-position steps,
Illinois' rule), takes the state there from the dense output, applies the jump and restarts the
stepper (a fresh buffer: the FSAL derivative is stale after the jump), keeping the step size.
Samples at ``j T/2`` come from the dense output. The basin runs every cell in a
``numba.prange`` loop and classifies it in the same compiled code with
``rockjit._engine.classify.classify``.

This is a user's code, not rockjit's: it uses ``numba.njit`` as nbkode does (rockjit's own
kernels go through ``rockjit._jit``).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from nbkode.buffer import AlignedBuffer
from nbkode.core import VariableStepOptions
from nbkode.runge_kutta import dop853_coefficients as _d853
from nbkode.runge_kutta.explicit import (DOP853, DOP853Interpolator, RkInterpolator,
                                         RungeKutta45)

from rockjit._engine.classify import classify

import common as C

NAME = "nbkode"
METHODS = ("RK45", "DOP853")
ST_DONE, ST_OVER, ST_REST, ST_MAXIMP = 0, 1, 2, 3

_P45 = np.ascontiguousarray(RungeKutta45.P, dtype=np.float64)
_D853 = np.ascontiguousarray(_d853.D, dtype=np.float64)
_A853 = np.ascontiguousarray(_d853.A, dtype=np.float64)
_C853 = np.ascontiguousarray(_d853.C, dtype=np.float64)
_N853 = int(_d853.N_STAGES)
_STAGES = {"RK45": RungeKutta45.stages, "DOP853": DOP853.stages}


def make_rhs(p: C.Params):
    """``rhs(t, y)`` of ``y = (theta, theta', side)``, the block's constants frozen in."""
    aw2, omega, phi, thc, xi = p.aw2, p.omega, p.phi, p.thc, p.xi

    @numba.njit(numba.float64[::1](numba.float64, numba.float64[::1]))
    def rhs(t, y):
        side = y[2]
        f = aw2 * math.sin(omega * t + phi)
        a = thc + side * y[0]
        out = np.empty(3)
        out[0] = y[1]
        out[1] = 0.75 * (f * math.sin(a) - side * math.cos(a) - xi * y[1])
        out[2] = 0.0
        return out

    return rhs


#: The uplift instant (docs/theory/impacts.md), compiled for the impact loop.
uplift_time = numba.njit(C.uplift_time)


def _build(method):
    """The compiled single-cell loop for ``method``: nbkode's step and interpolator."""
    step = RungeKutta45._step if method == "RK45" else DOP853._step
    n_stages = _STAGES[method]
    is45 = method == "RK45"

    @numba.njit
    def make_interp(rhs, cache, K):
        if is45:
            return RkInterpolator(cache, _P45, K)
        return DOP853Interpolator(cache, rhs, _N853, K, _D853, _A853, _C853)

    @numba.njit
    def locate(interp, side, ta, tb, ga, gb, which, thover):
        """Root of ``g(t) = side theta(t)`` (which 0) or ``thover - side theta(t)`` (1) on the
        dense output, bracketed by ``[ta, tb]`` with ``g(ta) = ga > 0 >= g(tb) = gb``."""
        last = 0
        for _ in range(200):
            if tb - ta <= 4e-16 * max(1.0, abs(tb)):
                break
            tm = (ta * gb - tb * ga) / (gb - ga)
            if not (ta < tm < tb) or _ % 4 == 3:
                tm = 0.5 * (ta + tb)
            th = interp.evaluate(tm)[0]
            gm = side * th if which == 0 else thover - side * th
            if gm > 0.0:
                ta, ga = tm, gm
                if last == 1:
                    gb *= 0.5
                last = 1
            else:
                tb, gb = tm, gm
                if last == -1:
                    ga *= 0.5
                last = -1
        return tb

    @numba.njit
    def run_cell(rhs, par, theta0, dtheta0, periods, rtol, atol, samples, per_imp, imp_t,
                 out):
        """One run from ``(theta0, dtheta0)`` over ``periods`` forcing periods.

        Fills ``samples[j] = (theta, theta')`` at ``t = j T/2``, ``per_imp[k]`` (impacts up to
        ``kT``), ``imp_t`` (impact times, as many as fit); ``out = (t, theta, theta', n_rhs)``.
        Returns ``(status, n_samples, n_impacts)``.
        """
        aw2, omega, phi = par[0], par[1], par[2]
        e, cot, thover, rest_speed, T = par[6], par[7], par[8], par[9], par[10]
        half = 0.5 * T
        n_samp = 2 * periods + 1
        t_end = periods * T
        max_imp = max(100_000, 10_000 * periods)
        options = VariableStepOptions(atol, rtol, 1e-15, np.inf, 0.2, 10.0, 0.9)
        K = np.empty((n_stages, 3))
        h = np.array(1e-3 * T)
        y = np.empty(3)
        y[0] = theta0
        y[1] = dtheta0
        side = 1.0 if (theta0 > 0 or (theta0 == 0 and dtheta0 > 0)) else (
            -1.0 if (theta0 < 0 or dtheta0 < 0) else 0.0)
        y[2] = side
        t = 0.0
        j = 0          # next sample index
        n_imp = 0
        n_rhs = 0
        status = ST_DONE
        for k in range(per_imp.shape[0]):
            per_imp[k] = 0
        if side == 0.0:
            # at rest from the start
            samples[0, 0] = 0.0
            samples[0, 1] = 0.0
            j = 1
        cache = AlignedBuffer(2, t, y, rhs(t, y))
        interp = make_interp(rhs, cache, K)
        while True:
            if side == 0.0:
                t_up = uplift_time(t, aw2, cot, omega, phi)
                while j < n_samp and j * half <= min(t_up, t_end):
                    samples[j, 0] = 0.0
                    samples[j, 1] = 0.0
                    if j % 2 == 0:
                        per_imp[j // 2] = n_imp
                    j += 1
                if t_up == math.inf:
                    status = ST_REST
                    t = min(t, t_end) if t_up == math.inf else t
                    break
                if t_up >= t_end:
                    t = t_end
                    y[0] = 0.0
                    y[1] = 0.0
                    break
                t = t_up
                side = 1.0 if math.sin(omega * t + phi) > 0 else -1.0
                y[0] = 0.0
                y[1] = 0.0
                y[2] = side
                cache = AlignedBuffer(2, t, y, rhs(t, y))
                interp = make_interp(rhs, cache, K)
                n_rhs += 1
            # one accepted step of nbkode's stepper
            t_old = cache.t
            th_old = cache.y[0]
            step(np.inf, rhs, cache, h, K, options, interp)
            t_new = cache.t
            th_new = cache.y[0]
            # event: impact (side theta crosses 0 downwards) or overturn
            ev = -1
            t_ev = t_new
            if side * th_new < 0.0:
                ev = 0
                t_ev = locate(interp, side, t_old, t_new, side * th_old, side * th_new, 0,
                              thover)
            if side * th_new >= thover:
                t_ov = locate(interp, side, t_old, t_new, thover - side * th_old,
                              thover - side * th_new, 1, thover)
                if ev < 0 or t_ov <= t_ev:
                    ev = 1
                    t_ev = t_ov
            t_stop = min(t_ev, t_end)
            while j < n_samp and j * half <= t_stop:
                ys = interp.evaluate(j * half)
                samples[j, 0] = ys[0]
                samples[j, 1] = ys[1]
                if j % 2 == 0:
                    per_imp[j // 2] = n_imp
                j += 1
            if t_end <= t_ev and t_end <= t_new:
                ys = interp.evaluate(t_end)
                t = t_end
                y[0] = ys[0]
                y[1] = ys[1]
                break
            if ev == 1:
                ys = interp.evaluate(t_ev)
                t = t_ev
                y[0] = ys[0]
                y[1] = ys[1]
                status = ST_OVER
                break
            if ev == 0:
                ys = interp.evaluate(t_ev)
                t = t_ev
                dth = e * ys[1]
                if n_imp < imp_t.shape[0]:
                    imp_t[n_imp] = t
                n_imp += 1
                if n_imp >= max_imp:
                    status = ST_MAXIMP
                    y[0] = 0.0
                    y[1] = dth
                    break
                side = -side
                y[0] = 0.0
                y[1] = dth
                y[2] = side
                if abs(dth) < rest_speed:
                    side = 0.0
                    y[1] = 0.0
                    y[2] = 0.0
                    continue
                cache = AlignedBuffer(2, t, y, rhs(t, y))
                interp = make_interp(rhs, cache, K)
                n_rhs += 1
        # counts of rhs evaluations are not kept by nbkode; estimate from the stages is left out
        out[0] = t
        out[1] = y[0]
        out[2] = y[1]
        out[3] = n_rhs
        return status, j, n_imp

    @numba.njit(parallel=True)
    def basin(rhs, par, th0, dth0, periods, rtol, atol, tol, pmax, lam_tol, labels):
        """Label of every cell ``(th0[i], dth0[i])``, in a ``prange`` loop."""
        n = th0.shape[0]
        k1 = periods
        k0 = int(round(0.8 * periods))
        for i in numba.prange(n):
            samples = np.zeros((2 * periods + 1, 2))
            per_imp = np.zeros(periods + 1, dtype=np.int64)
            imp_t = np.empty(1)
            out = np.empty(4)
            st, n_s, n_i = run_cell(rhs, par, th0[i], dth0[i], periods, rtol, atol, samples,
                                    per_imp, imp_t, out)
            if st == ST_OVER:
                labels[i] = 0
            elif st == ST_REST:
                labels[i] = 1
            elif st == ST_MAXIMP:
                labels[i] = 7
            else:
                s4 = np.zeros((k1 + 1, 4))
                h4 = np.zeros((k1 + 1, 4))
                for k in range(k1 + 1):
                    s4[k, 0] = samples[2 * k, 0]
                    s4[k, 1] = samples[2 * k, 1]
                    if k < k1:
                        h4[k, 0] = samples[2 * k + 1, 0]
                        h4[k, 1] = samples[2 * k + 1, 1]
                code, _p = classify(s4, h4, per_imp, k0, k1, math.nan, False, tol, pmax,
                                    lam_tol)
                labels[i] = code

    return run_cell, basin


_BUILT = {}
_RHS = {}


def _kernels(method):
    if method not in _BUILT:
        _BUILT[method] = _build(method)
    return _BUILT[method]


def _rhs(p):
    key = (p.aw2, p.omega, p.phi, p.thc, p.xi)
    if key not in _RHS:
        _RHS[key] = make_rhs(p)
    return _RHS[key]


_STATUS = {ST_DONE: C.DONE, ST_OVER: C.OVERTURNED, ST_REST: C.RESTED, ST_MAXIMP: C.MAX_IMPACTS}


def run(p: C.Params, theta0, dtheta0, periods, rtol, atol, method="DOP853",
        max_record=100_000):
    """One run; returns a :class:`common.PeerRun`."""
    run_cell, _ = _kernels(method)
    samples = np.zeros((2 * periods + 1, 2))
    per_imp = np.zeros(periods + 1, dtype=np.int64)
    imp_t = np.empty(max_record)
    out = np.empty(4)
    st, n_s, n_i = run_cell(_rhs(p), p.vector(), float(theta0), float(dtheta0), int(periods),
                            float(rtol), float(atol), samples, per_imp, imp_t, out)
    strobe, half = C.samples_from(2 * periods + 1, samples, n_s)
    return C.PeerRun(status=_STATUS[st], t=out[0], state=out[1:3].copy(),
                     impacts=imp_t[:min(n_i, max_record)].copy(), n_impacts=int(n_i),
                     strobe=strobe, half=half, per_imp=per_imp[:strobe.shape[0]].copy())


def basin(p: C.Params, theta0s, dtheta0s, periods, rtol, atol, method="DOP853"):
    """Labels ``(len(theta0s), len(dtheta0s))`` of the basin, every cell in a ``prange``."""
    _, kern = _kernels(method)
    TH, DTH = np.meshgrid(theta0s, dtheta0s, indexing="ij")
    labels = np.zeros(TH.size, dtype=np.int64)
    kern(_rhs(p), p.vector(), TH.ravel().copy(), DTH.ravel().copy(), int(periods),
         float(rtol), float(atol), C.TOL, C.PMAX, C.LAM_TOL, labels)
    return labels.reshape(TH.shape)
