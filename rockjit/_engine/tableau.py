"""The Dormand–Prince 5(4) tableau as data, and the table of one step's length built from it.

The coefficients are held exactly (rationals) and rounded once; every compiled step reads them
from here, either as the floats below or scaled by a step length in the table :func:`step_table`
fills. Which coefficients are zero is part of the data (:data:`COLS`): the stage chain
(:mod:`rockjit._engine.stages`) adds only the others, so an exactly zero coefficient never costs
a multiply-add on the step's critical path.

Notes
-----
Dormand & Prince (1980), in scipy's ``RK45`` naming (``A, B, C, E, P``; stages ``K``; the FSAL
derivative ``K[-1]``). Rows of the chain are numbered ``0..6``: stage ``i`` of ``A`` for
``i < 6``, and row 6 for the step's end (the weights ``B``, at ``c = 1``).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from .._jit import jit
from ..plugs.harmonic import advance_rotation

N_STAGES = 6

def _exact():
    """``A`` (with ``B`` as row 6) and ``C`` (with 1 for row 6) as rationals."""
    rows = [(), ((1, 5),), ((3, 40), (9, 40)), ((44, 45), (-56, 15), (32, 9)),
            ((19372, 6561), (-25360, 2187), (64448, 6561), (-212, 729)),
            ((9017, 3168), (-355, 33), (46732, 5247), (49, 176), (-5103, 18656)),
            ((35, 384), (0, 1), (500, 1113), (125, 192), (-2187, 6784), (11, 84))]
    a = [[Fraction(0)] * (N_STAGES + 1) for _ in range(N_STAGES + 1)]
    for i, row in enumerate(rows):
        for j, (n, d) in enumerate(row):
            a[i][j] = Fraction(n, d)
    c = [Fraction(0), Fraction(1, 5), Fraction(3, 10), Fraction(4, 5), Fraction(8, 9),
         Fraction(1), Fraction(1)]
    return a, c


_A7, _C7 = _exact()
#: the tableau's nodes, stage matrix (below the diagonal) and fifth-order weights, each the
#: correctly rounded float of its rational (as ``35 / 384`` is)
C = np.array(_C7[:N_STAGES], dtype=float)
A = np.array([row[:N_STAGES - 1] for row in _A7[:N_STAGES]], dtype=float)
B = np.array(_A7[N_STAGES][:N_STAGES], dtype=float)
E = np.array([-71 / 57600, 0.0, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525, 1 / 40])
P = np.array([
    [1.0, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 131558114200 / 32700410799, -68118460800 / 10900136933,
     87487479700 / 32700410799],
    [0.0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
    [0.0, 127303824393 / 49829197408, -318862633887 / 49829197408,
     701980252875 / 199316789632],
    [0.0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
    [0.0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
])


def _nystrom(a):
    """``A A`` (row 6: ``B A``), exactly: a stage's angle straight from the accelerations is
    ``x_i = x0 + h c_i v0 + h^2 (A A k)_i``, and the step's end ``x0 + h v0 + h^2 (B A k)``."""
    n = N_STAGES + 1
    return [[sum(a[i][m] * a[m][j] for m in range(N_STAGES)) for j in range(n)]
            for i in range(n)]


_AA7 = _nystrom(_A7)

#: ``A A`` and ``B A`` rounded (rows 0..5 and the step's end)
_AA = np.array([row[:N_STAGES] for row in _AA7[:N_STAGES]], dtype=float)
_BA = np.array(_AA7[N_STAGES][:N_STAGES], dtype=float)

#: the chain's coefficients as floats, row ``i`` = 0..6 (row 6: the step's end): ``"A"`` the
#: stage sums of derivatives (``A``, then ``B``), ``"AA"`` the Nystrom sums of accelerations
#: (``A A``, then ``B A``); ``"C"`` the rows' nodes
COEF = {"A": np.array(_A7, dtype=float), "AA": np.array(_AA7, dtype=float),
        "C": np.array(_C7, dtype=float)}

#: the columns ``j`` whose coefficient in row ``i`` is not exactly zero, per kind: the terms
#: the stage chain adds (``B[1]``, ``(B A)[1]``, ``(B A)[5]`` and ``(A A)[i, i - 1]`` are zero)
COLS = {kind: tuple(tuple(j for j in range(N_STAGES) if exact[i][j] != 0)
                    for i in range(N_STAGES + 1))
        for kind, exact in (("A", _A7), ("AA", _AA7))}


# ---- the table of one step's length ``tab`` (:func:`step_table`) -------------------------------
# rows 0..5: h A[i, :]; row 6: h B; rows 7 and 8: cos and sin of the forcing's phase advance
# omega c_i h to stage i (c_6 = 1, the step's end); rows 9..14: h^2 (A A)[i, :]; row 15:
# h^2 (B A); row 16: h c_i.
T_HB, T_ROTC, T_ROTS, T_HAA, T_HBA, T_HC = 6, 7, 8, 9, 15, 16
N_TAB = 17


def tab_entry(kind, i, j=0):
    """``(row, column)`` in the step's table of coefficient ``j`` of chain row ``i`` of
    ``kind`` (``"A"``, ``"AA"``; ``"C"``: the node, ``h c_i``)."""
    if kind == "A":
        return (i if i < N_STAGES else T_HB), j
    if kind == "AA":
        return (T_HAA + i if i < N_STAGES else T_HBA), j
    return T_HC, i


@jit(nrt=False, inline=True)
def step_table(omega, h, tab):
    """Fill ``tab`` for a step of length ``h`` (layout above). Only the lower triangles are
    written (an event costs two of these): the entries above are zero from allocation on."""
    h2 = h * h
    for i in range(N_STAGES):
        for j in range(i):
            tab[i, j] = h * A[i, j]
        for j in range(i - 1):
            tab[T_HAA + i, j] = h2 * _AA[i, j]
        tab[T_HB, i] = h * B[i]
        tab[T_HBA, i] = h2 * _BA[i]
    # the nodes, and the harmonic forcing's phase advances to them
    for i in range(N_STAGES + 1):
        c = C[i] if i < N_STAGES else 1.0
        tab[T_HC, i] = h * c
        tab[T_ROTC, i], tab[T_ROTS, i] = advance_rotation(omega, h, c)
