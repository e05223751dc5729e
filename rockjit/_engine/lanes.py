"""Several grid cells per thread in lockstep: the free-flight step of ``L`` lanes.

rockjit's step is a fixed-step Dormand–Prince step: every cell of a grid steps on the same time
grid, and an event inside a step is handled within that step. ``L`` cells advanced together
therefore stay on one grid; only their events differ. One cell's step is a chain of six stages,
each waiting for the last (its cost is latency, not arithmetic); ``L`` independent chains side
by side let the core overlap them, and written as one loop over lanes with no branch in it,
LLVM turns the lanes into SIMD vectors.

:func:`block_step_lanes` is :func:`rockjit._engine.step.block_step` (fast path, no slopes) for
``L`` lanes with the lane as the innermost, contiguous index of every array: the same
operations in the same order, fused multiply-adds included, so each lane's result is bit for
bit the single-lane step's (a vector FMA rounds once, as the scalar one).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import prange

from . import integrate as ig
from . import cell
from .._jit import cycles, fma, jit
from .stages import chain, compile_step
from .tableau import COLS
from ..model import (NEAR_RANGE, SINCOS_RANGE, accel_near, corner, initial_side, rotate,
                    sincos_poly)
from ..plugs.harmonic import uplift_time

__all__ = ["W", "bank", "block_step_lanes", "lane_tables", "run_lanes", "scalar_step"]

# rows of the lane-major step table (:func:`lane_tables`): the entries of integrate's table that
# the block's step reads (the chain's coefficients not exactly zero, :data:`rockjit._engine.tableau.COLS`), lane
# innermost; ``LANE_ROW[kind, i, j]`` is the row of coefficient ``j`` of chain row ``i``
LANE_ROW = {}
for _kind in ("A", "AA"):
    for _i in range(1, ig.N_STAGES + 1):
        for _j in COLS[_kind][_i]:
            LANE_ROW[_kind, _i, _j] = len(LANE_ROW)
for _i in range(1, ig.N_STAGES + 1):
    LANE_ROW["C", _i, 0] = len(LANE_ROW)
N_LTAB = len(LANE_ROW)


def _lane_rows():
    """``(row, column)`` of integrate's step table for each row of the lane table."""
    rows = [ig.tab_entry(*key) for key in LANE_ROW]
    return np.array(rows, dtype=np.int64)


LANE_ROWS = _lane_rows()


@jit(nrt=False)
def lane_tables(tab, lin, lane):
    """Copy the entries of integrate's step table ``tab`` that the block's step reads into
    column ``lane`` of the lanes' input ``lin`` (rows ``LI_TAB ..``)."""
    for r in range(N_LTAB):
        lin[(LI_TAB + r) * W + lane] = tab[LANE_ROWS[r, 0], LANE_ROWS[r, 1]]



#: Lanes at most (the row length of the lanes' arrays: a compile-time constant, so that the
#: vectoriser knows rows apart)
W = 8


# rows of the lanes' input ``lin`` and output ``lout`` (:func:`block_step_lanes`)
LI_X, LI_V, LI_K, LI_S, LI_C, LI_SG, LI_STHC, LI_CTHC, LI_XI, LI_THOVER = range(10)
LI_TAB = 10                     # N_LTAB rows: the step's table
N_LIN = LI_TAB + N_LTAB
LO_X, LO_V, LO_S, LO_C, LO_FAR = range(5)
LO_KV = LO_FAR                    # rows LO_KV + 1 .. LO_KV + 6
LO_KA = LO_KV + ig.N_STAGES       # rows LO_KA + 1 .. LO_KA + 6
LO_FAST = LO_KA + ig.N_STAGES + 1
N_LOUT = LO_FAST + 1


def _lane_coef(kind, i, j):
    """A coefficient of the chain (:func:`rockjit._engine.stages.chain`) in the lane's table."""
    return f"lin[tb + {LANE_ROW[kind, i, j]} * W]"


def _lane_stage(i):
    """Stage ``i``'s acceleration on the fast path: the corner rotated to the step's start."""
    return (f"P, Q = corner(ftl[(j * 7 + {i}) * W + l], side, st, ct)\n"
            f"Pr, Qr = rotate(P, Q, sl, cl)\n"
            f"k{i} = accel_near(Pr, Qr, x{i}, v{i}, dmp)")


_STEP_LANES = (
    ["for l in range(n):"]
    + ["    " + ln for ln in (
        ["x0 = lin[LI_X * W + l]",
         "v0 = lin[LI_V * W + l]",
         "k0 = lin[LI_K * W + l]",
         "sl = lin[LI_S * W + l]",
         "cl = lin[LI_C * W + l]",
         "side = lin[LI_SG * W + l]",
         "st = lin[LI_STHC * W + l]",
         "ct = lin[LI_CTHC * W + l]",
         "dmp = lin[LI_XI * W + l]",
         "tb = LI_TAB * W + l  # the lane's step table: row r at tb + r W"]
        + chain(_lane_stage, _lane_coef, arith="fma", form="nystrom")
        + ["xe = x0 + x6",
           "s6, c6 = sincos_poly(xe)",
           "f = max(max(max(abs(x1), abs(x2)), max(abs(x3), abs(x4))), max(abs(x5), abs(x6)))",
           "far = max(f * (1.0 / NEAR_RANGE), abs(xe) * (1.0 / SINCOS_RANGE))",
           "lout[LO_FAR * W + l] = far"]
        + [f"lout[(LO_KV + {i}) * W + l] = v{i}" for i in range(1, ig.N_STAGES + 1)]
        + [f"lout[(LO_KA + {i}) * W + l] = k{i}" for i in range(1, ig.N_STAGES + 1)]
        + ["lout[LO_X * W + l] = xe",
           "lout[LO_V * W + l] = v6",
           "lout[LO_S * W + l] = s6",
           "lout[LO_C * W + l] = c6",
           "g0 = side * x0",
           "g1 = side * xe",
           "graze = (g0 > 0.0) & (side * v0 < 0.0) & (side * v6 > 0.0)",
           "fast = ((side != 0.0) & (far <= 1.0) & (g1 < lin[LI_THOVER * W + l]) & (g1 >= 0.0)"
           " & (not graze))",
           "lout[LO_FAST * W + l] = 1.0 if fast else 0.0",
           "lin[LI_X * W + l] = xe if fast else x0",
           "lin[LI_V * W + l] = v6 if fast else v0",
           "lin[LI_K * W + l] = k6 if fast else k0",
           "lin[LI_S * W + l] = s6 if fast else sl",
           "lin[LI_C * W + l] = c6 if fast else cl"])])

block_step_lanes = compile_step("block_step_lanes", "n, j, lin, lout, ftl", _STEP_LANES,
                                globals(), jit(nrt=False), doc="""One Dormand–Prince step of the block in ``n`` lanes at once (fast path, no slopes).

    Parameters
    ----------
    n : int
        Lanes.
    j : int
        The step's index in the forcing period (the same in every lane).
    lin : ndarray, (N_LIN * W,)
        Each lane's state and constants, row ``r`` of lane ``l`` at ``r * W + l`` (rows
        ``I_*``): angle, velocity, acceleration, and sine and cosine of the angle at the step's
        start; the corner (as a float: +1, -1, or 0 at rest), ``sin(thc)``, ``cos(thc)``, the
        damping, the overturning angle; the step's table (``LI_TAB + r``, :func:`lane_tables`).
        A lane whose step is *fast* (below) has its state advanced to the step's end here.
    lout : ndarray, (N_LOUT * W,)
        Receives the stages' velocities and accelerations (``LO_KV + i``, ``LO_KA + i``, rows
        ``i = 1..6``: ``K[i, 0]`` and ``K[i, 1]`` of :func:`rockjit._engine.step.block_step`), the
        angle and velocity at the step's end, the sine and cosine of that angle, ``far``
        (``> 1``: the step left the polynomials' range) and ``LO_FAST``: 1 when the step is
        accepted as it is (in flight, in range, and none of the events that
        :func:`rockjit._engine.events.detect` looks for), else 0 (the lane's state is left as it was,
        for the single-lane code to take the step).
    ftl : ndarray, (N * 7 * W,)
        Each lane's forcing acceleration at stage ``i`` of step ``j`` at ``(7 j + i) W + l``.

    Notes
    -----
    The stage chain is :mod:`rockjit._engine.stages`' (Nystrom's form), the lane as the loop
    index.
    Three flat arrays whose rows lie a compile-time stride ``W`` apart: LLVM's loop vectoriser
    then needs three overlap checks (with one array per quantity it gives up: "too many memory
    checks"). The state is written back here, as a vector, so that the next step's vector loads
    never wait on single-lane stores (a failed store-to-load forwarding cost three times the
    step).
    """)


# ---------------------------------------------------------------------------------------------
# a grid's cells in lanes
# ---------------------------------------------------------------------------------------------

# layout of a lane's loop state: integers ``st`` and floats ``fs`` (the variables of
# rockjit._engine.integrate.drive)
(LS_STATUS, LS_SIDE, LS_NIMP, LS_STEP, LS_JPER, LS_KPER, LS_JQR, LS_JREC, LS_NCOL, LS_NCOLWIN,
 LS_CELL) = range(11)
N_ST = 11
LF_TT, LF_MAXERR, LF_TLIFT, LF_TUP = range(4)
# LF_TUP: at rest, the instant the forcing lifts the block (rockjit.plugs.harmonic.uplift_time)
# the forcing and grid the lane's tables were made for: alpha omega^2, omega, phi, h, N
LF_KEY = 4
N_FS = LF_KEY + 5


@jit(nrt=False, inline=True)
def scalar_step(TANGENT, st, fs, par, ipar, out, w, pre, prof, counts):
    """One grid step of a lane on the scalar path: :func:`rockjit._engine.integrate.grid_step`, the
    single-lane loop's own step (closed-form forcing, no trajectory), with the lane's loop
    variables kept in ``st`` and ``fs``. Used for every step the lanes' fast path does not take
    (an event, a rest phase, a stage out of the polynomial's range), so that each lane runs
    exactly the single-lane code there. ``pre``: the grid step's first Runge–Kutta step is in
    ``w`` already (``K[1:]``, ``ynew``, ``trig[2:4]``: the vector step's, which equals it when it
    stayed in range), so it is not taken again. With ``prof``, ``counts[6:13]`` receive the
    cycles of its parts (see :func:`rockjit._engine.integrate.grid_step`)."""
    s = ig.grid_step(None, TANGENT, False, prof, pre,
                     ig.Loop(st[LS_STATUS], fs[LF_TT], st[LS_SIDE], st[LS_NIMP], st[LS_STEP],
                             st[LS_JPER], st[LS_KPER], st[LS_JQR], st[LS_JREC], st[LS_NCOL],
                             st[LS_NCOLWIN], fs[LF_TLIFT], fs[LF_MAXERR]),
                     par, ipar, out, w, counts)
    st[LS_STATUS] = s.status
    st[LS_SIDE] = s.side
    st[LS_NIMP] = s.n_imp
    st[LS_STEP] = s.step
    st[LS_JPER] = s.j_per
    st[LS_KPER] = s.k_per
    st[LS_JQR] = s.j_qr
    st[LS_JREC] = s.j_rec
    st[LS_NCOL] = s.n_col
    st[LS_NCOLWIN] = s.n_col_win
    fs[LF_TT] = s.t
    fs[LF_MAXERR] = s.max_err
    fs[LF_TLIFT] = s.t_lift


#: A block of lanes' arrays: each lane's loop state (``st``, ``fs``), parameters (``par``,
#: ``N_PARW``), the lanes' step input and output (``lin``, ``lout``) and forcing table
#: (``ftl``), and each lane's
#: :data:`rockjit._engine.integrate.Outputs` and :data:`rockjit._engine.integrate.Work` arrays (first index:
#: the lane).
Bank = namedtuple("Bank", "st fs par lin lout ftl strobe half impacts traj lam_run per_imp iout "
                          "fout K states lam tab_h tab fr jac trig ftab")


def bank(periods, n_per, n_imp_pts):
    """Fresh arrays for ``W`` lanes (a run's outputs as :func:`rockjit._engine.kernel._grid` makes
    them, the work arrays as :func:`rockjit._engine.integrate._run`)."""
    return _bank(periods, n_per, max(n_imp_pts, 1))


@jit
def _bank(periods, n_per, cap):
    n_st = ig.N_STAGES + 1
    return Bank(np.zeros((W, N_ST), dtype=np.int64), np.zeros((W, N_FS)),
                np.zeros((W, ig.N_PARW)), np.zeros(N_LIN * W), np.zeros(N_LOUT * W),
                np.zeros(n_per * n_st * W),
                np.zeros((W, periods + 1, 4)), np.zeros((W, periods + 1, 4)),
                np.zeros((W, cap, 3)), np.zeros((W, 1, 5)), np.zeros((W, 1, 3)),
                np.zeros((W, periods + 1), dtype=np.int64),
                np.zeros((W, ig.N_IOUT), dtype=np.int64), np.zeros((W, ig.N_FOUT)),
                np.zeros((W, n_st, 2)), np.zeros((W, 4, 2)), np.zeros((W, 4)),
                np.zeros((W, ig.N_TAB, n_st)), np.zeros((W, ig.N_TAB, n_st)),
                np.zeros((W, n_st)), np.zeros((W, n_st)), np.zeros((W, 4)),
                np.zeros((W, n_per, ig.N_FTAB)))


@jit(nrt=False, inline=True)
def lane_outputs(b, l):
    return ig.Outputs(b.strobe[l], b.half[l], b.impacts[l], b.traj[l], b.lam_run[l],
                      b.per_imp[l], b.iout[l], b.fout[l])


@jit(nrt=False, inline=True)
def lane_work(b, l):
    s = b.states[l]
    return ig.Work(b.K[l], s[0], s[1], s[2], s[3], b.lam[l], b.tab_h[l], b.tab[l], b.fr[l],
                   b.jac[l], b.trig[l], b.ftab[l])


@jit(nrt=False)
def _zero(a):
    f = a.reshape(a.size)
    for m in range(f.size):
        f[m] = 0


@jit(nrt=False)
def _load(l, i, y0s, pars, ipar, b):
    """Start cell ``i`` in lane ``l`` (:func:`rockjit._engine.integrate._run` and the start of its
    loop, on fresh arrays). Returns whether it runs (False: it ended before its first step).

    The stroboscopic samples (``strobe``, ``half``) and impact counts (``per_imp``) are not
    cleared: a run writes each row before anything reads it (the period test and the
    classifier read the periods completed so far), and clearing them, ~36 kB a cell at 500
    periods, cost an early-stopped cell of the study's basin (~12 periods) several percent."""
    _zero(b.impacts[l])
    _zero(b.traj[l])
    _zero(b.lam_run[l])
    _zero(b.fout[l])
    _zero(b.K[l])
    _zero(b.states[l])
    _zero(b.lam[l])
    _zero(b.tab[l])
    _zero(b.fr[l])
    _zero(b.jac[l])
    _zero(b.trig[l])
    _zero(b.iout[l])
    par = b.par[l]
    for m in range(ig.N_PARW):
        par[m] = 0.0
    for m in range(ig.N_PAR):
        par[m] = pars[i, m]
    par[ig.P_STHC] = math.sin(pars[i, ig.P_THC])
    par[ig.P_CTHC] = math.cos(pars[i, ig.P_THC])
    out = lane_outputs(b, l)
    w = lane_work(b, l)
    y0 = y0s[i]
    side0 = initial_side(y0[0], y0[1])
    st = b.st[l]
    fs = b.fs[l]
    # the lane's tables serve the next cell too when its forcing and grid are the same (every
    # cell of a basin): they are made by the same code from the same numbers
    same = (fs[LF_KEY] == par[ig.P_AW2] and fs[LF_KEY + 1] == par[ig.P_OMEGA]
            and fs[LF_KEY + 2] == par[ig.P_PHI] and fs[LF_KEY + 3] == par[ig.P_H]
            and fs[LF_KEY + 4] == ipar[ig.I_N])
    if not same:
        _zero(b.tab_h[l])
        _zero(b.ftab[l])
        ig.tables(None, par, ipar, w)
        lane_tables(w.tab_h, b.lin, l)
        for jj in range(ipar[ig.I_N]):
            for s in range(ig.N_STAGES + 1):
                b.ftl[(jj * (ig.N_STAGES + 1) + s) * W + l] = w.ftab[jj, s]
        fs[LF_KEY] = par[ig.P_AW2]
        fs[LF_KEY + 1] = par[ig.P_OMEGA]
        fs[LF_KEY + 2] = par[ig.P_PHI]
        fs[LF_KEY + 3] = par[ig.P_H]
        fs[LF_KEY + 4] = ipar[ig.I_N]
    status = ig.start_state(None, None, y0, side0, par, ipar, out, w)
    for m in range(N_ST):
        st[m] = 0
    st[LS_STATUS] = status
    st[LS_SIDE] = side0
    st[LS_NCOL] = out.iout[ig.O_NCOL]
    st[LS_NCOLWIN] = st[LS_NCOL] if ipar[ig.I_WINDOW] == 0 else 0
    st[LS_CELL] = i
    fs[LF_TT] = 0.0
    fs[LF_MAXERR] = 0.0
    fs[LF_TLIFT] = -math.inf
    fs[LF_TUP] = _uplift(st, fs, par)
    b.lin[LI_STHC * W + l] = par[ig.P_STHC]
    b.lin[LI_CTHC * W + l] = par[ig.P_CTHC]
    b.lin[LI_XI * W + l] = par[ig.P_XI]
    _refresh(l, b)
    return status == ig.RUNNING and ipar[ig.I_N] * ipar[ig.I_PERIODS] > 0


#: A lane at rest skips its scalar steps while the uplift lies this many steps' lengths
#: beyond the grid point (margin for the rounding of uplift_time at another instant): the
#: single-lane code holds it at rest there (REST_HOLD), and so do the lanes, bit for bit.
REST_MARGIN = 1e-9


@jit(nrt=False, inline=True)
def _uplift(st, fs, par):
    """At rest (``side`` 0): the next uplift after the lane's time; else -inf."""
    if st[LS_SIDE] != 0 or st[LS_STATUS] != ig.RUNNING:
        return -math.inf
    return uplift_time(fs[LF_TT], par[ig.P_AW2], par[ig.P_COT], par[ig.P_OMEGA], par[ig.P_PHI])


@jit(nrt=False, inline=True)
def _refresh(l, b):
    """The lane's step input from its state (after a load or a step)."""
    s = b.states[l]
    b.lin[LI_X * W + l] = s[0, 0]
    b.lin[LI_V * W + l] = s[0, 1]
    b.lin[LI_K * W + l] = b.K[l, 0, 1]
    b.lin[LI_S * W + l] = b.trig[l, 0]
    b.lin[LI_C * W + l] = b.trig[l, 1]
    b.lin[LI_SG * W + l] = b.st[l, LS_SIDE]
    b.lin[LI_THOVER * W + l] = b.par[l, ig.P_THOVER]


@jit(nrt=False, inline=True)
def _sync(l, b):
    """The lane's single-lane state from its step input (the fast path keeps it there only)."""
    s = b.states[l]
    s[0, 0] = b.lin[LI_X * W + l]
    s[0, 1] = b.lin[LI_V * W + l]
    b.K[l, 0, 0] = b.lin[LI_V * W + l]
    b.K[l, 0, 1] = b.lin[LI_K * W + l]
    b.trig[l, 0] = b.lin[LI_S * W + l]
    b.trig[l, 1] = b.lin[LI_C * W + l]


@jit(nrt=False, inline=True)
def _stages(l, b):
    """The vector step's stages and end into the lane's work arrays, as
    :func:`rockjit._engine.step.rk_step` would leave them (no tangent)."""
    K = b.K[l]
    for i in range(1, ig.N_STAGES + 1):
        K[i, 0] = b.lout[(LO_KV + i) * W + l]
        K[i, 1] = b.lout[(LO_KA + i) * W + l]
    s = b.states[l]
    s[2, 0] = b.lout[LO_X * W + l]  # ynew
    s[2, 1] = b.lout[LO_V * W + l]
    b.trig[l, 2] = b.lout[LO_S * W + l]
    b.trig[l, 3] = b.lout[LO_C * W + l]


@jit(nrt=False)
def _end(l, ipar, cpar, n_pts, n_imp_pts, res, pts, imp_pts, n_got, n_imp_got, b):
    """Lane ``l``'s run has ended: its outputs (:func:`rockjit._engine.integrate.drive`'s end), its
    classification and samples (:func:`rockjit._engine.kernel._grid`); the lane is free."""
    st = b.st[l]
    fs = b.fs[l]
    par = b.par[l]
    out = lane_outputs(b, l)
    w = lane_work(b, l)
    status = st[LS_STATUS]
    if status == ig.RUNNING:
        status = ig.DONE
    out.iout[ig.O_NCOL] = st[LS_NCOL]
    ig.finish(None, None, status, fs[LF_TT], st[LS_STEP], st[LS_NIMP], st[LS_NCOLWIN],
              fs[LF_MAXERR], ipar, par, out, w)
    i = st[LS_CELL]
    cell._classify(None, status, ipar, cpar, out, res[i])
    cell._collect(i, par[ig.P_H] * ipar[ig.I_N], n_pts, n_imp_pts, out, res, pts, imp_pts,
                n_got, n_imp_got)
    st[LS_CELL] = -1


@jit(nrt=False)
def run_lanes(n_lanes, i0, i1, y0s, pars, ipar, cpar, n_pts, n_imp_pts, res, pts, imp_pts,
              n_got, n_imp_got, b, prof, counts):
    """Cells ``i0 .. i1 - 1`` through ``n_lanes <= W`` lanes (no tangent vectors), a freed
    lane refilled from the next pending cell at the next period's start (all lanes then step
    through the period together: one forcing row for all); outputs as
    :func:`rockjit._engine.kernel._grid`'s.

    Each grid step: :func:`block_step_lanes` for all lanes at once, which accepts the step of
    every lane in flight whose step has no event, stays in the polynomials' range; a lane at
    rest whose uplift (computed once when it came to rest) lies beyond the grid point is held
    there, as the single-lane code would hold it; every other lane's step (an event, the end of
    a rest phase) is taken again by :func:`scalar_step`, the single-lane code. A lane's
    arithmetic is the single-lane kernel's either way, so its results are bit for bit those of
    :func:`rockjit._engine.kernel._grid` (the running error estimate ``max_err`` is not kept on
    the fast path: no grid output reads it). ``counts``: the fast steps (with the steps held at
    rest) and the scalar steps, the vector steps taken, and with ``prof`` the cycles
    (``readcyclecounter``) spent in the vector steps, in the scalar steps, and in all, then the parts of the scalar steps
    (:func:`scalar_step`); without, the cycle counter is not read (its reads cost ~10 % of a
    basin's time).
    """
    c_start = cycles() if prof else 0
    n_per = ipar[ig.I_N]
    total = n_per * ipar[ig.I_PERIODS]
    half = n_per // 2
    lin = b.lin
    lout = b.lout
    ftl = b.ftl
    nxt = i0
    for l in range(W):
        b.st[l, LS_CELL] = -1
    j = np.int64(0)  # the step's index in the period, the same in every lane (int64, not the
    # literal 0: block_step_lanes would be compiled once more for the literal)
    while True:
        busy = 0
        for l in range(n_lanes):
            while j == 0 and b.st[l, LS_CELL] < 0 and nxt < i1:
                i = nxt
                nxt += 1
                if not _load(l, i, y0s, pars, ipar, b):
                    b.st[l, LS_CELL] = i
                    _end(l, ipar, cpar, n_pts, n_imp_pts, res, pts, imp_pts, n_got,
                         n_imp_got, b)
            if b.st[l, LS_CELL] >= 0:
                busy += 1
        if busy == 0:
            if nxt >= i1:
                break
            j = 0  # no lane busy: the next cells start now
            continue
        c0 = cycles() if prof else 0
        # all W lanes, one vector, whatever n_lanes; the count is read from an array's shape
        # so that LLVM does not know it: a known count of 8 unrolls the loop fully, and the
        # unrolled code is not vectorised
        block_step_lanes(b.st.shape[0], j, lin, lout, ftl)
        c1 = cycles() if prof else 0
        counts[2] += 1
        counts[3] += c1 - c0
        for l in range(n_lanes):
            st = b.st[l]
            if st[LS_CELL] < 0:
                continue
            fast = lout[LO_FAST * W + l] != 0.0
            hl = b.par[l, ig.P_H]
            # at rest with the uplift beyond the grid point: held there, as the scalar step
            # would (rockjit._engine.integrate.leave_rest), without taking it
            held = (st[LS_SIDE] == 0
                    and b.fs[l, LF_TUP] - (st[LS_STEP] + 1) * hl > REST_MARGIN * hl)
            if fast or held:
                counts[0] += 1
                if fast:
                    iout = b.iout[l]
                    iout[ig.O_RHS] += ig.N_STAGES
                    iout[ig.O_SUBSTEPS] += 1
                step = st[LS_STEP] + 1
                st[LS_STEP] = step
                t = step * b.par[l, ig.P_H]
                b.fs[l, LF_TT] = t
                if not (math.isfinite(lin[LI_X * W + l]) and math.isfinite(lin[LI_V * W + l])):
                    st[LS_STATUS] = ig.NONFINITE
                elif j + 1 != n_per and j + 1 != half:
                    st[LS_JPER] = j + 1
                else:
                    _sync(l, b)
                    status, j_per, k_per, j_qr, j_rec, collapsed = ig.grid_point(
                        None, None, False, t, step, st[LS_SIDE], st[LS_NIMP], st[LS_NCOL],
                        step - 1 >= ipar[ig.I_WINDOW] * n_per, ipar, b.par[l],
                        lane_outputs(b, l), lane_work(b, l), st[LS_JPER], st[LS_KPER],
                        st[LS_JQR], st[LS_JREC])
                    st[LS_STATUS] = status
                    st[LS_JPER] = j_per
                    st[LS_KPER] = k_per
                    st[LS_JQR] = j_qr
                    st[LS_JREC] = j_rec
            else:
                counts[1] += 1
                c0 = cycles() if prof else 0
                _sync(l, b)
                pre = st[LS_SIDE] != 0 and lout[LO_FAR * W + l] <= 1.0
                if pre:
                    _stages(l, b)
                scalar_step(None, st, b.fs[l], b.par[l], ipar, lane_outputs(b, l),
                            lane_work(b, l), pre, prof, counts)
                _refresh(l, b)
                b.fs[l, LF_TUP] = _uplift(st, b.fs[l], b.par[l])
                counts[4] += (cycles() - c0) if prof else 0
            if st[LS_STATUS] != ig.RUNNING or st[LS_STEP] >= total:
                _sync(l, b)
                _end(l, ipar, cpar, n_pts, n_imp_pts, res, pts, imp_pts, n_got, n_imp_got, b)
        j += 1
        if j == n_per:
            j = 0
    if prof:
        counts[5] += cycles() - c_start


#: Cells per block of lanes: a block is one task of the parallel loop, its cells run through
#: one set of lanes (a freed lane takes the block's next pending cell).
BLOCK = 256


@jit(parallel=True)
def grid_lanes(n_lanes, block, y0s, pars, ipar, cpar, n_pts, n_imp_pts, res, pts, imp_pts,
               n_got, n_imp_got, prof, counts):
    """:func:`rockjit._engine.kernel._grid` without tangent vectors, ``n_lanes`` cells at a time per
    thread: blocks of ``block`` cells, each through :func:`run_lanes` on fresh arrays. A cell's
    results do not depend on its block, lane or thread. ``counts[g]`` receives block ``g``'s
    step counts, and with ``prof`` its cycle counts (:func:`run_lanes`)."""
    n = y0s.shape[0]
    nb = (n + block - 1) // block
    for g in prange(nb):
        b = _bank(ipar[ig.I_PERIODS], ipar[ig.I_N], max(n_imp_pts, 1))
        run_lanes(n_lanes, g * block, min(n, (g + 1) * block), y0s, pars, ipar, cpar, n_pts,
                  n_imp_pts, res, pts, imp_pts, n_got, n_imp_got, b, prof, counts[g])
