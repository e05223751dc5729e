"""The harmonic kernels' layout: status codes, the arguments' named slots, event kinds.

The kernels take and fill flat arrays; the names below say what each slot holds. They are
the contract between :mod:`rockjit._engine.kernel`, which packs the arrays and reads them
back, and the compiled code (:mod:`rockjit._engine.integrate`, :mod:`~rockjit._engine.step`,
:mod:`~rockjit._engine.events`).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from ..result import STATUSES

# ---- status codes (kernels return these; the Python layer explains them) ----------------------
RUNNING = -1
DONE = 0          # reached the requested end time
OVERTURNED = 1    # |theta| reached the overturning threshold
REST = 2          # at rest, and the forcing can never lift the block again
MAX_IMPACTS = 3   # the impact bound was reached
NONFINITE = 4     # a non-finite number appeared (never expected; a guard, not a result)
SETTLED = 5       # stopped early: the stroboscopic orbit settled (see analysis)

STATUS_NAMES = dict(enumerate(STATUSES))  # code -> name (rockjit.result.STATUSES)

#: What a run writes: stroboscopic samples at kT and kT + T/2 (rows theta, theta', r, s), the
#: impacts (rows t, theta'-, theta'+; a ring holding the latest when there are more), the
#: recorded trajectory (rows t, theta, theta', r, s), the running exponents at kT (columns
#: lambda1, lambda2 as S(kT)/kT, and the number of collapses of the tangent vectors before kT),
#: the number of impacts before kT, and the scalar outputs ``iout`` and ``fout`` below.
Outputs = namedtuple("Outputs", "strobe half impacts traj lam_run per_imp iout fout")

#: The loop's work arrays: stages ``K``; states ``y, ytmp, ynew, yev``; ``lam`` (sums of the
#: logs of the stretches, overall and in the window); step tables for the grid step (``tab_h``)
#: and for substeps (``tab``); the stage forcing ``fr`` and slopes ``jac``; ``trig``, the sine
#: and cosine of theta at the start and the end of a step; ``ftab``, the closed-form forcing
#: at each grid step of a period (columns ``FT_*`` below).
Work = namedtuple("Work", "K y ytmp ynew yev lam tab_h tab fr jac trig ftab")

#: The driver loop's state between two grid steps (:func:`rockjit._engine.integrate.grid_step`
#: takes it and returns the next): the status code, the time, the corner (0 at rest), the
#: impacts so far, the grid steps taken, the grid steps into the current period, the periods
#: completed, the grid steps since the last renormalisation and since the last trajectory
#: point, the tangent vectors' collapses (all, and in the averaging window), the latest
#: uplift's instant and the largest error estimate so far.
Loop = namedtuple("Loop", "status t side n_imp step j_per k_per j_qr j_rec n_col n_col_win "
                          "t_lift max_err")

# ---- layout of the float parameter vector ``par`` ---------------------------------------------
P_THC, P_XI, P_E, P_AW2, P_OMEGA, P_PHI, P_COT, P_THOVER, P_REST, P_H, P_SETTLE_TOL, P_LAW, \
    P_LAW_SHAPE = range(13)
N_PAR = 13
# P_E: the block's coefficient of restitution; P_LAW, P_LAW_SHAPE: its law's kind and shape
# at an impact (rockjit.laws.impact.restitution_at; kind 0: the coefficient P_E itself)
# ... which the kernel copies into a working vector with constants derived from it:
P_STHC, P_CTHC = range(N_PAR, N_PAR + 2)  # sin(thc), cos(thc)
N_PARW = N_PAR + 2

# ---- layout of the integer settings ``ipar`` ---------------------------------------------------
I_N, I_PERIODS, I_MAXIMP, I_STRIDE, I_WINDOW, I_SETTLE, I_QR, I_PMAX, I_CONTINUE = range(9)
N_IPAR = 9
# I_CONTINUE: 1 to integrate on past the overturning threshold (the study's own runs did; the
# first crossing is recorded in F_TOVER), 0 to stop there (the physical rule, docs/theory/impacts.md).
# I_QR: grid steps between renormalisations of the tangent vectors (0: never).
# I_SETTLE: repetitions of a period that count as settled (0: never stop early); I_PMAX: the
# longest period looked for.

# ---- layout of the integer outputs ``iout`` ----------------------------------------------------
O_STATUS, O_STEPS, O_IMPACTS, O_RHS, O_NSTROBE, O_NHALF, O_NTRAJ, O_NREST, O_NREST_WIN, \
    O_SUBSTEPS, O_NIMP_WIN, O_PERIOD, O_NCOL, O_UNCONVERGED, O_RESTEP = range(15)
N_IOUT = 15
# O_NCOL: collapses of the tangent vectors (rest phases, impacts with e = 0): every perturbation
# died there. O_UNCONVERGED: events whose Newton polish did not reach its tolerance. O_RESTEP:
# events located by genuine steps because the step's interpolant was not trusted (see locate).

# ---- layout of the float outputs ``fout`` ------------------------------------------------------
F_T, F_TH, F_DTH, F_R, F_S, F_MAXERR, F_LAM1, F_LAM2, F_WINTIME, F_V = range(10)
F_TOVER = F_V + 4  # F_V..F_V+3: the tangent matrix at the end, column-major
N_FOUT = F_TOVER + 1  # F_TOVER: the first instant |theta| reached theta_over (nan: never)

# ---- columns of the forcing table ``ftab`` (one row per grid step ``j`` of a period) -----------
# 0..6: the forcing acceleration alpha omega^2 sin(phase) at stage i of step j (6: its end);
# FT_DF0, FT_DF1: its time derivative alpha omega^3 cos(phase) at the step's start and end (the
# jerk and snap of the event interpolant, :func:`end_derivs`); FT_SIN, FT_COS: sin and cos of the
# phase phi + 2 pi j / N at the step's start (a step from an event instant rotates them,
# :func:`~rockjit._engine.step.phase_before_grid`).
FT_DF0, FT_DF1, FT_SIN, FT_COS = 7, 8, 9, 10
N_FTAB = 11

# Kinds of event.
EV_NONE, EV_IMPACT, EV_OVERTURN, EV_UPLIFT = 0, 1, 2, 3

BISECT_ITERS = 60
NEWTON_ITERS = 8
#: the transient kernel's root finder along genuine steps: Newton's and bisection's iterations
ROOT_ITERS = 60
DELTA_EULER = 1e-8  # see locate_step
LOCATE_TOL = DELTA_EULER  # see locate_interp

# Constants handed to the step's inlined pieces go as int64 and bool values (np.int64(0),
# np.bool_(True), OFF_GRID), not as Python literals: numba types a literal argument by its value
# and compiles the piece once more for each value (a cold start's time), while LLVM folds the
# constant once the piece is inlined either way.
OFF_GRID = np.bool_(False)  # rk_step's ``tabulated`` for a step off the grid (from an event)
