"""Several grid cells per thread in lockstep (issue 17): the free-flight step of ``L`` lanes.

rockjit's step is a fixed-step Dormand–Prince step: every cell of a grid steps on the same time
grid, and an event inside a step is handled within that step. ``L`` cells advanced together
therefore stay on one grid; only their events differ. One cell's step is a chain of six stages,
each waiting for the last (its cost is latency, not arithmetic); ``L`` independent chains side
by side let the core overlap them, and written as one loop over lanes with no branch in it,
LLVM turns the lanes into SIMD vectors.

:func:`block_step_lanes` is :func:`rockjit.integrate.block_step` (fast path, no slopes) for
``L`` lanes with the lane as the innermost, contiguous index of every array: the same
operations in the same order, fused multiply-adds included, so each lane's result is bit for
bit the single-lane step's (a vector FMA rounds once, as the scalar one).
"""

from __future__ import annotations

import numpy as np

from . import integrate as ig
from ._jit import fma, jit
from .model import NEAR_RANGE, SINCOS_RANGE, accel_near, corner, rotate, sincos_poly

__all__ = ["block_step_lanes", "lane_tables"]

# rows of the lane-major step table ``tabl`` (:func:`lane_tables`): the entries of
# integrate's table that the block's step reads, lane innermost
(L_A10, L_A20, L_A21, L_A30, L_A31, L_A32, L_A40, L_A41, L_A42, L_A43, L_A50, L_A51, L_A52,
 L_A53, L_A54, L_B0, L_B2, L_B3, L_B4, L_B5, L_AA20, L_AA30, L_AA31, L_AA40, L_AA41, L_AA42,
 L_AA50, L_AA51, L_AA52, L_AA53, L_BA0, L_BA2, L_BA3, L_BA4, L_C1, L_C2, L_C3, L_C4, L_C5,
 L_C6) = range(40)
N_LTAB = 40


def _lane_rows():
    """``(row, column)`` of integrate's step table for each row of the lane table."""
    rows = [(1, 0), (2, 0), (2, 1), (3, 0), (3, 1), (3, 2), (4, 0), (4, 1), (4, 2), (4, 3),
            (5, 0), (5, 1), (5, 2), (5, 3), (5, 4)]
    rows += [(ig.T_HB, j) for j in (0, 2, 3, 4, 5)]
    rows += [(ig.T_HAA + 2, 0), (ig.T_HAA + 3, 0), (ig.T_HAA + 3, 1), (ig.T_HAA + 4, 0),
             (ig.T_HAA + 4, 1), (ig.T_HAA + 4, 2), (ig.T_HAA + 5, 0), (ig.T_HAA + 5, 1),
             (ig.T_HAA + 5, 2), (ig.T_HAA + 5, 3)]
    rows += [(ig.T_HBA, j) for j in (0, 2, 3, 4)]
    rows += [(ig.T_HC, i) for i in range(1, 7)]
    assert len(rows) == N_LTAB
    return np.array(rows, dtype=np.int64)


LANE_ROWS = _lane_rows()


@jit(nrt=False)
def lane_tables(tab, lin, lane):
    """Copy the entries of integrate's step table ``tab`` that the block's step reads into
    column ``lane`` of the lanes' input ``lin`` (rows ``I_TAB ..``)."""
    for r in range(N_LTAB):
        lin[(I_TAB + r) * W + lane] = tab[LANE_ROWS[r, 0], LANE_ROWS[r, 1]]



#: Lanes at most (the row length of the lanes' arrays: a compile-time constant, so that the
#: vectoriser knows rows apart)
W = 8

# rows of the lanes' input ``lin`` and output ``lout`` (:func:`block_step_lanes`)
I_X, I_V, I_K, I_S, I_C, I_SG, I_STHC, I_CTHC, I_XI = range(9)
I_FR = 9                       # 7 rows: the forcing acceleration at each stage
I_TAB = I_FR + ig.N_STAGES + 1  # N_LTAB rows: the step's table
N_LIN = I_TAB + N_LTAB
O_X, O_V, O_S, O_C, O_FAR = range(5)
O_KV = O_FAR                    # rows O_KV + 1 .. O_KV + 6
O_KA = O_KV + ig.N_STAGES       # rows O_KA + 1 .. O_KA + 6
N_LOUT = O_KA + ig.N_STAGES + 1

@jit(nrt=False)
def block_step_lanes(n, lin, lout):
    """One Dormand–Prince step of the block in ``n`` lanes at once (fast path, no slopes).

    Parameters
    ----------
    n : int
        Lanes.
    lin : ndarray, (N_LIN, L)
        What each lane's step reads, lane innermost (rows ``I_*``): angle, velocity,
        acceleration, and sine and cosine of the angle at the step's start; the corner (as a
        float, +1 or -1), ``sin(thc)``, ``cos(thc)``, the damping; the forcing acceleration at
        each stage (``I_FR + i``); the step's table (``I_TAB + r``, :func:`lane_tables`).
    lout : ndarray, (N_LOUT, L)
        Receives the stages' velocities and accelerations (``O_KV + i``, ``O_KA + i``, rows
        ``i = 1..6``: ``K[i, 0]`` and ``K[i, 1]`` of :func:`rockjit.integrate.block_step`), the
        angle and velocity at the step's end, the sine and cosine of that angle, and ``far``
        (``> 1``: the lane must redo its step on the slow path).

    Notes
    -----
    Two arrays, one read and one written: LLVM's loop vectoriser then needs a single overlap
    check (with one array per quantity it gives up: "too many memory checks").
    """
    for l in range(n):
        xl = lin[(I_X) * W + l]
        vl = lin[(I_V) * W + l]
        kl = lin[(I_K) * W + l]
        sl = lin[(I_S) * W + l]
        cl = lin[(I_C) * W + l]
        side = lin[(I_SG) * W + l]
        st = lin[(I_STHC) * W + l]
        ct = lin[(I_CTHC) * W + l]
        dmp = lin[(I_XI) * W + l]
        d1 = lin[(I_TAB + L_C1) * W + l] * vl
        v1 = fma(lin[(I_TAB + L_A10) * W + l], kl, vl)
        P, Q = corner(lin[(I_FR + 1) * W + l], side, st, ct)
        Pr, Qr = rotate(P, Q, sl, cl)
        k1 = accel_near(Pr, Qr, d1, v1, dmp)
        d2 = fma(lin[(I_TAB + L_AA20) * W + l], kl, lin[(I_TAB + L_C2) * W + l] * vl)
        v2 = fma(lin[(I_TAB + L_A21) * W + l], k1, fma(lin[(I_TAB + L_A20) * W + l], kl, vl))
        P, Q = corner(lin[(I_FR + 2) * W + l], side, st, ct)
        Pr, Qr = rotate(P, Q, sl, cl)
        k2 = accel_near(Pr, Qr, d2, v2, dmp)
        d3 = fma(lin[(I_TAB + L_AA31) * W + l], k1, fma(lin[(I_TAB + L_AA30) * W + l], kl, lin[(I_TAB + L_C3) * W + l] * vl))
        v3 = fma(lin[(I_TAB + L_A32) * W + l], k2, fma(lin[(I_TAB + L_A31) * W + l], k1, fma(lin[(I_TAB + L_A30) * W + l], kl, vl)))
        P, Q = corner(lin[(I_FR + 3) * W + l], side, st, ct)
        Pr, Qr = rotate(P, Q, sl, cl)
        k3 = accel_near(Pr, Qr, d3, v3, dmp)
        d4 = fma(lin[(I_TAB + L_AA42) * W + l], k2, fma(lin[(I_TAB + L_AA41) * W + l], k1,
                 fma(lin[(I_TAB + L_AA40) * W + l], kl, lin[(I_TAB + L_C4) * W + l] * vl)))
        v4 = fma(lin[(I_TAB + L_A43) * W + l], k3, fma(lin[(I_TAB + L_A42) * W + l], k2, fma(lin[(I_TAB + L_A41) * W + l], k1,
                 fma(lin[(I_TAB + L_A40) * W + l], kl, vl))))
        P, Q = corner(lin[(I_FR + 4) * W + l], side, st, ct)
        Pr, Qr = rotate(P, Q, sl, cl)
        k4 = accel_near(Pr, Qr, d4, v4, dmp)
        d5 = fma(lin[(I_TAB + L_AA53) * W + l], k3, fma(lin[(I_TAB + L_AA52) * W + l], k2, fma(lin[(I_TAB + L_AA51) * W + l], k1,
                 fma(lin[(I_TAB + L_AA50) * W + l], kl, lin[(I_TAB + L_C5) * W + l] * vl))))
        v5 = fma(lin[(I_TAB + L_A54) * W + l], k4, fma(lin[(I_TAB + L_A53) * W + l], k3, fma(lin[(I_TAB + L_A52) * W + l], k2,
                 fma(lin[(I_TAB + L_A51) * W + l], k1, fma(lin[(I_TAB + L_A50) * W + l], kl, vl)))))
        P, Q = corner(lin[(I_FR + 5) * W + l], side, st, ct)
        Pr, Qr = rotate(P, Q, sl, cl)
        k5 = accel_near(Pr, Qr, d5, v5, dmp)
        d6 = fma(lin[(I_TAB + L_BA4) * W + l], k4, fma(lin[(I_TAB + L_BA3) * W + l], k3, fma(lin[(I_TAB + L_BA2) * W + l], k2,
                 fma(lin[(I_TAB + L_BA0) * W + l], kl, lin[(I_TAB + L_C6) * W + l] * vl))))
        v6 = fma(lin[(I_TAB + L_B5) * W + l], k5, fma(lin[(I_TAB + L_B4) * W + l], k4, fma(lin[(I_TAB + L_B3) * W + l], k3,
                 fma(lin[(I_TAB + L_B2) * W + l], k2, fma(lin[(I_TAB + L_B0) * W + l], kl, vl)))))
        P, Q = corner(lin[(I_FR + 6) * W + l], side, st, ct)
        Pr, Qr = rotate(P, Q, sl, cl)
        k6 = accel_near(Pr, Qr, d6, v6, dmp)
        x6 = xl + d6
        s6, c6 = sincos_poly(x6)
        f = max(max(max(abs(d1), abs(d2)), max(abs(d3), abs(d4))), max(abs(d5), abs(d6)))
        lout[(O_FAR) * W + l] = max(f * (1.0 / NEAR_RANGE), abs(x6) * (1.0 / SINCOS_RANGE))
        lout[(O_KV + 1) * W + l] = v1
        lout[(O_KV + 2) * W + l] = v2
        lout[(O_KV + 3) * W + l] = v3
        lout[(O_KV + 4) * W + l] = v4
        lout[(O_KV + 5) * W + l] = v5
        lout[(O_KV + 6) * W + l] = v6
        lout[(O_KA + 1) * W + l] = k1
        lout[(O_KA + 2) * W + l] = k2
        lout[(O_KA + 3) * W + l] = k3
        lout[(O_KA + 4) * W + l] = k4
        lout[(O_KA + 5) * W + l] = k5
        lout[(O_KA + 6) * W + l] = k6
        lout[(O_X) * W + l] = x6
        lout[(O_V) * W + l] = v6
        lout[(O_S) * W + l] = s6
        lout[(O_C) * W + l] = c6
