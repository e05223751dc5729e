"""One grid cell's results: a finished run classified into its row of scalars, and its samples
collected into the grid's arrays. Shared by the grid kernel (:mod:`rockjit._engine.kernel`) and the
lockstep lanes (:mod:`rockjit._engine.lanes`), so that neither imports the other."""

from __future__ import annotations

import math

from . import integrate as ig
from .._jit import jit
from .classify import classify, lam_between
from ..result import OVERTURN, REST, UNRESOLVED

# layout of the classification settings ``cpar`` (float)
C_TOL, C_LAMTOL = range(2)
# layout of a cell's scalar results ``res`` (float)
R_LABEL, R_PERIOD, R_LAM1, R_LAM2, R_T, R_NIMP, R_K0, R_K1, R_STATUS, R_TOVER, R_MOTION = \
    range(11)
N_RES = 11
# R_TOVER: the first overturning instant (nan: never); R_MOTION: the behaviour of the motion
# the run settled on, even after the block fell (runs that continue past overturning; the label
# of such a cell is overturn, the study's rule)


@jit(nrt=False)
def _classify(TANGENT, status, ipar, cpar, out, res):
    """Classify a cell's finished run (status code ``status``, outputs ``out``) into ``res``."""
    iout = out.iout
    k1 = iout[ig.O_NSTROBE] - 1
    if status == ig.SETTLED:
        p = iout[ig.O_PERIOD]
        # exactly the samples settled_period compared: (k1 - reps p - p, k1]
        k0 = max(0, k1 - ipar[ig.I_SETTLE] * p - p + 1)
    else:
        k0 = ipar[ig.I_WINDOW]
    lam1 = math.nan
    lam2 = math.nan
    if TANGENT is not None:
        la, lb = lam_between(out.lam_run, k0, k1)
        lam1 = max(la, lb)  # sorted: lambda1 >= lambda2 (see run_single)
        lam2 = min(la, lb)
    label = UNRESOLVED
    period = 0
    if status == ig.OVERTURNED:
        label = OVERTURN
    elif status == ig.REST:
        label = REST
        lam1 = -math.inf
        lam2 = -math.inf
    elif status == ig.DONE or status == ig.SETTLED:
        label, period = classify(out.strobe, out.half, out.per_imp, k0, k1, lam1,
                                 TANGENT is not None, cpar[C_TOL], ipar[ig.I_PMAX],
                                 cpar[C_LAMTOL])
    res[R_MOTION] = label
    t_over = out.fout[ig.F_TOVER]
    if t_over == t_over:  # fell once and went on: overturn, the study's rule
        label = OVERTURN
    res[R_TOVER] = t_over
    res[R_LABEL] = label
    res[R_PERIOD] = period
    res[R_LAM1] = lam1
    res[R_LAM2] = lam2
    res[R_T] = out.fout[ig.F_T]
    res[R_NIMP] = iout[ig.O_IMPACTS]
    res[R_K0] = k0
    res[R_K1] = k1
    res[R_STATUS] = status


@jit(nrt=False)
def _collect(i, T, n_pts, n_imp_pts, out, res, pts, imp_pts, n_got, n_imp_got):
    """Cell ``i``'s stroboscopic samples and impact section from its finished run ``out``
    (classified into ``res[i]``; ``T`` the forcing period)."""
    cap = out.impacts.shape[0]
    k0 = int(res[i, R_K0])
    k1 = int(res[i, R_K1])
    st = int(res[i, R_STATUS])
    bounded = st == ig.DONE or st == ig.SETTLED  # it ran to a classified stretch
    if n_pts > 0:
        m = 0
        if bounded:
            for k in range(max(k0, k1 - n_pts + 1), k1 + 1):
                pts[i, m, 0] = out.strobe[k, 0]
                pts[i, m, 1] = out.strobe[k, 1]
                m += 1
        n_got[i] = m
    if n_imp_pts > 0:
        m = 0
        if bounded:
            nimp = out.iout[ig.O_IMPACTS]
            t_from = k0 * T
            first = max(0, nimp - cap)
            for q in range(first, nimp):
                row = q % cap
                if out.impacts[row, 0] >= t_from:
                    tt = out.impacts[row, 0]
                    imp_pts[i, m, 0] = tt - T * math.floor(tt / T)
                    imp_pts[i, m, 1] = out.impacts[row, 1]
                    m += 1
        n_imp_got[i] = m
