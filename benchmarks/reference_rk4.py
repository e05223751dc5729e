"""A plain reference basin: classical Runge–Kutta 4 at a fixed step, written the obvious way.

The yardstick of the grid benchmarks (``bench_versions.py``, case ``rk4-basin``): what a careful
first implementation of the study's basin looks like, so that rockjit's kernel can be measured
against something other than itself. It is deliberately plain, not deliberately slow:

- numba ``njit(parallel=True)``, one ``prange`` iteration per cell, no caching tricks;
- the field written straight from the model's equation on corner ``s``,
  ``theta'' = 3/4 (f sin(thc + s theta) - s cos(thc + s theta) - xi theta')`` with
  ``f = alpha omega^2 sin(omega t + phi)``, libm's sine and cosine at every stage;
- the classical 4-stage Runge–Kutta step on the same grid as rockjit's (``h = T/N``, the
  basin's ``N``, 64 by default), so that the stroboscopic samples fall on it;
- an impact when theta changes sign over a step (a dip through 0 and back within one step is
  not looked for), located by a safeguarded Newton iteration on re-taken RK4 steps from the
  step's start (to 1e-13 of the step), started by linear interpolation, or from the step's end
  for a flight that started on theta = 0 (Newton then approaches the far root from its
  concave side); then the jump ``theta' <- e theta'``, the corner switched, and the rest of the
  step taken from the impact;
- rest when the speed after an impact is below the block's ``rest_speed``, lifted at
  :func:`rockjit.plugs.harmonic.uplift_time`; overturning when ``|theta|`` reaches
  ``theta_over`` at a step's end (the run stops, as the study's basins do);
- labels by rockjit's own classifier on the samples at ``kT`` and ``kT + T/2`` over the window.

It reads the packed inputs of a basin plan (:func:`rockjit.basin.plan`: ``y0s``,
``pars``, ``ipar``, ``cpar``) and returns each cell's label; no early stop. Its labels agree
with rockjit's full-length labels on the study's basin in the cells checked by
``bench_versions.py`` (the agreement is printed with the timing).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from rockjit._engine import integrate as ig
from rockjit._engine.classify import classify
from rockjit.plugs.harmonic import uplift_time
from rockjit.result import OVERTURN, REST

RUNNING, DONE, OVERTURNED, RESTED = 0, 1, 2, 3


@numba.njit(fastmath=False)
def _acc(t, th, v, side, thc, xi, aw2, omega, phi):
    f = aw2 * math.sin(omega * t + phi)
    a = thc + side * th
    return 0.75 * (f * math.sin(a) - side * math.cos(a) - xi * v)


@numba.njit(fastmath=False)
def _rk4(t, th, v, h, side, thc, xi, aw2, omega, phi):
    k1x = v
    k1v = _acc(t, th, v, side, thc, xi, aw2, omega, phi)
    k2x = v + 0.5 * h * k1v
    k2v = _acc(t + 0.5 * h, th + 0.5 * h * k1x, k2x, side, thc, xi, aw2, omega, phi)
    k3x = v + 0.5 * h * k2v
    k3v = _acc(t + 0.5 * h, th + 0.5 * h * k2x, k3x, side, thc, xi, aw2, omega, phi)
    k4x = v + h * k3v
    k4v = _acc(t + h, th + h * k3x, k4x, side, thc, xi, aw2, omega, phi)
    return (th + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x),
            v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v))


@numba.njit(fastmath=False)
def _cell(th, v, par, n_per, periods, strobe, half, per_imp):
    thc = par[ig.P_THC]
    xi = par[ig.P_XI]
    e = par[ig.P_E]
    aw2 = par[ig.P_AW2]
    omega = par[ig.P_OMEGA]
    phi = par[ig.P_PHI]
    cot = par[ig.P_COT]
    th_over = par[ig.P_THOVER]
    rest = par[ig.P_REST]
    h = par[ig.P_H]
    side = 1 if th > 0.0 else (-1 if th < 0.0 else (1 if v > 0.0 else (-1 if v < 0.0 else 0)))
    t = 0.0
    n_imp = 0
    strobe[0, 0] = th
    strobe[0, 1] = v
    per_imp[0] = 0
    for step in range(n_per * periods):
        t_end = (step + 1) * h
        while t < t_end:
            if side == 0:
                t_up = uplift_time(t, aw2, cot, omega, phi)
                if t_up == math.inf:
                    return RESTED
                if t_up >= t_end:
                    t = t_end
                    break
                t = t_up
                th = 0.0
                v = 0.0
                side = 1 if math.sin(omega * t + phi) > 0.0 else -1
            hh = t_end - t
            th1, v1 = _rk4(t, th, v, hh, side, thc, xi, aw2, omega, phi)
            if side * th1 >= th_over:
                return OVERTURNED
            if side * th1 < 0.0:
                # an impact in this step: Newton on re-taken steps, in a safeguarded bracket
                lo = 0.0
                hi = hh
                if side * th > 0.0:
                    tau = hh * th / (th - th1)
                else:
                    tau = hh  # a flight from theta = 0: from the end, on the concave side
                for _ in range(50):
                    x, dx = _rk4(t, th, v, tau, side, thc, xi, aw2, omega, phi)
                    if side * x > 0.0:
                        lo = tau
                    else:
                        hi = tau
                    tn = tau - x / dx if dx != 0.0 else 0.5 * (lo + hi)
                    if not (lo < tn < hi):
                        tn = 0.5 * (lo + hi)
                    if abs(tn - tau) <= 1e-13 * hh:
                        tau = tn
                        break
                    tau = tn
                x, dx = _rk4(t, th, v, tau, side, thc, xi, aw2, omega, phi)
                t = t + tau
                th = 0.0
                v = e * dx
                side = -side
                n_imp += 1
                if abs(v) < rest:
                    v = 0.0
                    side = 0
                continue
            th = th1
            v = v1
            t = t_end
        j = (step + 1) % n_per
        k = (step + 1) // n_per
        if j == 0:
            strobe[k, 0] = th
            strobe[k, 1] = v
            per_imp[k] = n_imp
        elif j == n_per // 2:
            half[k, 0] = th
            half[k, 1] = v
    return DONE


@numba.njit(parallel=True, fastmath=False)
def basin_rk4(y0s, pars, ipar, cpar):
    """Each cell's label (rockjit's codes) from the packed inputs of a basin plan."""
    n = y0s.shape[0]
    n_per = ipar[ig.I_N]
    periods = ipar[ig.I_PERIODS]
    labels = np.zeros(n, dtype=np.int64)
    for i in numba.prange(n):
        strobe = np.zeros((periods + 1, 2))
        half = np.zeros((periods + 1, 2))
        per_imp = np.zeros(periods + 1, dtype=np.int64)
        status = _cell(y0s[i, 0], y0s[i, 1], pars[i], n_per, periods, strobe, half, per_imp)
        if status == OVERTURNED:
            labels[i] = OVERTURN
        elif status == RESTED:
            labels[i] = REST
        else:
            lab, _ = classify(strobe, half, per_imp, ipar[ig.I_WINDOW], periods, math.nan,
                              False, cpar[0], ipar[ig.I_PMAX], cpar[1])
            labels[i] = lab
    return labels
