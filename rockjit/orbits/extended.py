"""The extended systems whose zeros are the codimension-one curves in the forcing plane
``(alpha, omega)``: the flow with both forcing parameters free (:class:`PlaneFlow`), each curve
type's fixed-point equations and defining condition, and their Jacobian (:class:`Extended`).
The continuation that follows a curve is :mod:`.tracer`'s, driven by :mod:`.curves`.

Definitions
-----------
Extended system
    The unknowns are ``y = (theta, theta', alpha, omega)``: the orbit's point at the
    stroboscopic section and the two forcing parameters. The equations are the orbit's
    fixed-point equations and one defining condition (Kuznetsov 2004 ch. 10; Govaerts 2000):

    ==================== ============================= ====================================
    curve                fixed-point equations          defining condition
    ==================== ============================= ====================================
    fold                 ``P^p(x) - x = 0``             ``det(M - I) = 0``
    fold (symmetric)     ``x + Phi_{pT/2}(x) = 0``      ``det(M - I) = 0``
    symmetry breaking    ``x + Phi_{pT/2}(x) = 0``      ``det(M - I) = 0``
    period doubling      ``P^p(x) - x = 0``             ``det(M + I) = 0``
    grazing (impact)     either, with its impact count  ``theta`` at the turning point that
                                                        nears ``theta = 0`` is 0
    grazing (overturn)   either                         ``max|theta| = theta_over``
    ==================== ============================= ====================================

    On the half map of a symmetric orbit, ``M = A^2`` (``A`` the half map's Jacobian), and
    ``det(M - I) = det(A - I) det(A + I)``: the symmetric fold (``A``'s eigenvalue +1) and the
    symmetry-breaking pitchfork (-1) share the condition, and cannot meet: that would need
    ``det A = -1``, while ``|det A| < 1`` (dissipation). In a 2-D map the determinant *is* the
    minimally augmented test function (the bordered system's scalar is a multiple of it).
Jacobian
    ``[G_x G_alpha G_omega]`` with ``G = (fixed-point equations, condition)``. Of the full map's
    equations ``G_x = M - I`` is exact: ``M``, the monodromy, from the tangent flow with the
    saltation matrix at every impact (:mod:`.shooting`). Forward differences (``1e-7``
    relative) give the parameter columns, the half map's ``G_x`` and every derivative of the
    condition (the derivative of ``det M`` needs the second variation, which the engine does
    not integrate; the grazing condition's, the flow to the turning point). Newton's method on
    the bordered system ``[G_y; t^T]`` starts from the last point's Jacobian, updates its
    differenced part by Broyden's rank-one formula and its exact part ``M - I`` at every
    iterate, and takes a new one where the residual falls by less than a factor 20: an
    iteration costs one run over ``p`` periods, a new Jacobian five.
"""

from __future__ import annotations

import math

import numpy as np

from ..excitation import OMEGA_RANGE, Harmonic
from .shooting import Flow, failure

__all__: list[str] = []

_TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------------------------------------
# the flow with both forcing parameters free
# ---------------------------------------------------------------------------------------------

class PlaneFlow(Flow):
    """:class:`rockjit.orbits.shooting.Flow` whose parameter ``lam`` is the pair
    ``(alpha, omega)``: the solver's residuals, Newton's method and analysis work unchanged."""

    def __init__(self, block, phase, n_steps, shooting):
        super().__init__(block, Harmonic(), "plane", n_steps, phase, shooting)

    def params(self, lam):
        return float(lam[0]), float(lam[1])

    def valid(self, lam):
        return lam[0] >= 0.0 and OMEGA_RANGE[0] <= lam[1] <= OMEGA_RANGE[1] and \
            lam[0] * lam[1] ** 2 <= 1e8

    def period(self, lam):
        return _TWO_PI / float(lam[1])


# ---------------------------------------------------------------------------------------------
# the extended system
# ---------------------------------------------------------------------------------------------

class CurveEval:
    """One evaluation of the extended system at ``y``: ``G = (F, g)``, the monodromy, the run."""

    __slots__ = ("ok", "reason", "F", "g", "M", "r", "y", "deficit")

    def __init__(self, ok, reason=None, F=None, g=None, M=None, r=None, y=None, deficit=None):
        self.ok, self.reason, self.F, self.g, self.M, self.r, self.y = ok, reason, F, g, M, r, y
        self.deficit = deficit  # off a grazing condition's side: how far (estimated)

    @property
    def G(self):
        return np.r_[self.F, self.g]


class Extended:
    """The extended system of one curve type (module docstring, "Extended system")."""

    def __init__(self, solver, ctype, p, form, nimp, depth=None, fd_rel=1e-7):
        self.s = solver
        self.flow = solver.flow
        self.type = ctype
        self.p = p
        self.form = form
        self.nimp = nimp
        self.depth = depth
        self.c = -1.0 if ctype == "period_doubling" else 1.0
        self.fd = fd_rel
        self.I2 = np.eye(2)

    def __call__(self, y, j):
        lam = (y[2], y[3])
        if not self.flow.valid(lam) or not np.all(np.isfinite(y)):
            return CurveEval(False, "no_convergence")
        p = self.p
        r = self.flow.run(y[:2], lam, p, j, True)
        why = failure(r)
        if self.depth is not None and (why or self.depth.count(r, lam) != self.nimp):
            # (through a rest phase, the crossing's speed is below the Zeno cut-off: unknown)
            return CurveEval(False, why or "grazing", r=r,
                             deficit=None if why in ("rest", "passes_through_rest") else
                             self.depth.deficit(r, lam, j))
        if why:
            return CurveEval(False, why, r=r)
        x = y[:2]
        if self.form == "full":
            F = r.strobe[p, :2] - x
        else:
            F = x + r.strobe_half[(p - 1) // 2, :2]
        M = r.extra["tangent"]
        if self.depth is None:
            g = float(np.linalg.det(M - self.c * self.I2))
        else:
            g = self.depth(r, lam, j)
            if g is None:
                return CurveEval(False, "grazing", r=r)
        return CurveEval(True, None, F, g, M, r, np.array(y, float))

    def tol(self, ev):
        """Tolerances of ``F`` and ``g`` at an evaluation."""
        m = max(1.0, float(np.abs(ev.M).sum(axis=1).max()))
        ft = self.s.tol * m
        gt = 1e-12 * max(1.0, float(np.abs(ev.y[:2]).max())) if self.depth is not None \
            else 1e-11 * m
        return ft, gt

    def jacobian(self, ev, j):
        """``dG/dy`` (3 x 4): ``M - I`` exact for the full map's equations, forward differences
        elsewhere (for the grazing condition, backward where the forward point is off its
        side). ``None`` if a difference cannot be taken."""
        J = np.empty((3, 4))
        G0 = ev.G
        for i in range(4):
            h = self.fd * max(1.0, abs(ev.y[i]))
            col = None
            for sgn in (1.0, -1.0):
                y2 = ev.y.copy()
                y2[i] += sgn * h
                e2 = self(y2, j)
                if e2.ok:
                    col = (e2.G - G0) / (sgn * h)
                    break
                if self.depth is None:
                    break
            if col is None:
                return None
            J[:, i] = col
        if self.form == "full":
            J[:2, :2] = ev.M - self.I2
        return J

    def refresh(self, J, ev):
        """The chord Jacobian's exact part at a new iterate."""
        if self.form == "full":
            J = J.copy()
            J[:2, :2] = ev.M - self.I2
        return J
