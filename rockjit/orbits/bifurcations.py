"""Bifurcations of periodic orbits along a branch: detected between two branch points and
located, the fold, symmetry-breaking pitchfork, period doubling and Neimark–Sacker by test
functions and the grazings (and the ends at overturning and rest) by bisection.

Definitions and choices
-----------------------
Test functions
    On consecutive branch points (Kuznetsov 2004 ch. 10; Seydel 2010 ch. 5): ``det(M - I)`` (a
    real multiplier through +1), ``det(M + I)`` (through -1), ``det(M) - 1`` with a complex pair
    (Neimark–Sacker). A sign change is located by Brent's method along the chord between the two
    points, each trial a corrected point on the branch (the hyperplane through it normal to the
    chord), to ``1e-8`` or better in the parameter.
Symmetric orbits
    On a symmetric orbit a multiplier +1 of ``M = A^2`` (``A`` the half map's Jacobian) is a
    symmetry-breaking pitchfork when ``A``'s eigenvalue crosses -1 and a fold when it crosses +1
    (then ``det(I - A)`` changes sign too); on other orbits it is a fold. Period doubling and
    symmetry breaking are followed onto the new branch (``2p``, resp. ``p`` without symmetry)
    from the located point along the critical eigenvector (:mod:`.arclength`).
Neimark–Sacker
    It cannot occur in this model unless ``e = 1`` and ``xi = 0``: ``det M = e^(2n)
    exp(-3 xi pT / 4)`` with ``n`` impacts per cycle (the trace of the variational equation is
    ``-3 xi / 4`` and each saltation matrix has determinant ``e^2``, docs/theory/exponents.md), so a complex
    pair always has ``|mu| < 1``; the test is kept for completeness.
Grazing
    A step whose orbit has a different number of impacts per cycle brackets a grazing, located
    by bisection on the count (to ``param_tol``). Near a grazing from the side without the extra
    impact the map's derivative blows up (di Bernardo et al. 2008, ch. 6) and the corrector
    fails before the count changes: the orbit is then followed by damped Newton at fixed
    parameter values to where it stops existing, by bisection. Overturning and rest end a branch likewise, located the same way and
    reported as a grazing (of ``theta_over``, of rest).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .grazing import Depth, deficit_gradient, push_onto, slow_pair
from .shooting import Info, failure
from .types import Bifurcation, OrbitRefused

#: Nothing here is called by users: :class:`Locator` is the continuation's base class
#: (:mod:`.arclength`), which reports what it locates as :class:`rockjit.orbits.Bifurcation`.
__all__: list[str] = []


_HOP = ("an excursion that touches down twice at low speed and comes back shrinks to a "
        "grazing (located on the orbit without those impacts, which meets it there)")


class LocateFailed(Exception):
    """A trial point of a located bifurcation could not be corrected onto the branch."""


def unit(v):
    """``v`` over its Euclidean norm (``v`` itself when that is 0)."""
    n = float(np.linalg.norm(v))
    return v / n if n > 0 else v


@dataclass
class BranchPoint:
    """A converged point of a branch and what its tangent run says about the orbit."""

    y: np.ndarray     # (theta, theta', lambda) at section j
    j: int            # the section the continuation works on at this point
    jt: int           # the section its recorded trajectory starts from
    info: Info
    iters: int = 0


class Locator:
    """Branch points from corrected states, and the bifurcations between two of them.

    The continuation (:class:`rockjit.orbits.arclength.Continuer`) is a ``Locator`` with a
    solver ``s`` (:class:`rockjit.orbits.shooting.Solver`), its flow, the range ``lo, hi``,
    ``param_tol`` and ``switching``."""

    # -- points -------------------------------------------------------------------------------
    def point(self, y, j, form, p, ev):
        """A branch point from a converged corrector (one more tangent run for the half map)."""
        if form == "full":
            r = ev.r
        else:
            r = self.flow.run(y[:2], y[2], p, j, True)
            if failure(r):
                return None
        return BranchPoint(np.array(y, float), j, j, self.s.analyse(r, y[2], p, j))

    # -- bifurcations between two branch points -----------------------------------------------
    def detect(self, a, b, form, p, bifs, requests):
        """Locate each bifurcation whose test function changes sign from ``a`` to ``b``
        (appended to ``bifs``; a branch to switch onto, to ``requests``)."""
        pa, pb = a.info.psi, b.info.psi
        if pa[0] * pb[0] < 0:
            self.locate(a, b, 0, form, p, bifs, requests)
        if pa[1] * pb[1] < 0:
            self.locate(a, b, 1, form, p, bifs, requests)
        if pa[2] * pb[2] < 0 and (pa[3] < 0 or pb[3] < 0):
            self.locate(a, b, 2, form, p, bifs, requests)

    def _chord_point(self, a, c, n, sv, form, p):
        ok, y, ev, _, why = self.s.correct(a.y + sv * c, n, form, p, a.j)
        P = self.point(y, a.j, form, p, ev) if ok else None
        if P is None:
            raise LocateFailed(why or "passes_through_rest")
        return P

    def locate(self, a, b, idx, form, p, bifs, requests):
        """Brent's method on test function ``psi[idx]`` along the chord from a to b."""
        from scipy.optimize import brentq
        calls0 = self.flow.calls
        c = b.y - a.y
        n = unit(c)
        cache = {0.0: a, 1.0: b}

        def P(sv):
            if sv not in cache:
                cache[sv] = self._chord_point(a, c, n, sv, form, p)
            return cache[sv]

        located = True
        xtol = min(1e-6, max(1e-13, 0.1 * self.param_tol / max(abs(c[2]), 1e-300)))
        try:
            sv = brentq(lambda u: P(u).info.psi[idx], 0.0, 1.0, xtol=xtol, maxiter=100)
            Q = P(sv)
            detail = ""
        except (LocateFailed, RuntimeError, ValueError) as exc:
            located = False
            fa, fb = a.info.psi[idx], b.info.psi[idx]
            sv = fa / (fa - fb)
            try:
                Q = P(sv)
            except LocateFailed:
                Q = a if abs(fa) < abs(fb) else b
            detail = f"bracketing solve failed ({exc}); interpolated"
        if idx == 0:
            kind = "fold"
            if form == "sym":
                # M = A^2 with A the half map's Jacobian: A's eigenvalue -1 breaks the symmetry,
                # +1 is a fold of symmetric orbits, where det(I - A) = det(dF_half/dx) changes
                # sign too
                ja = self._half_det(a, p)
                jb = self._half_det(b, p)
                kind = "fold" if (ja is not None and jb is not None and ja * jb < 0) \
                    else "symmetry_breaking"
        elif idx == 1:
            kind = "period_doubling"
        else:
            if Q.info.psi[3] >= 0:
                return  # a neutral saddle (real mu1 mu2 = 1), no bifurcation
            kind = "neimark_sacker"
        lam = float(Q.y[2])
        alpha, omega = self.flow.params(lam)
        bif = Bifurcation(
            type=kind, parameter=self.flow.parameter, value=lam, alpha=alpha, omega=omega,
            period=p, multipliers=Q.info.mu.copy(), state=Q.info.cycle[0].copy(),
            cycle=Q.info.cycle.copy(), cycle_half=Q.info.half.copy(), branch=-1,
            neighbours=(float(a.y[2]), float(b.y[2])),
            neighbour_multipliers=np.array([a.info.mu, b.info.mu]), located=located,
            n_simulate=0, detail=detail, has_mirror=not Q.info.symmetric)
        bif.n_simulate = self.flow.calls - calls0
        bifs.append(bif)
        if self.switching and kind in ("period_doubling", "symmetry_breaking"):
            requests.append((bif, Q, p))

    def _half_det(self, P, p):
        ev = self.s.sym(P.y[:2], P.y[2], p, P.j)
        if not ev.ok:
            return None
        J = self.s.jac_x("sym", ev, p, P.j)
        return None if J is None else float(np.linalg.det(J))

    def _graze_bif(self, P, a_lam, b_lam, mu_a, mu_b, p, detail, calls0):
        lam = float(P.y[2])
        alpha, omega = self.flow.params(lam)
        return Bifurcation(
            type="grazing", parameter=self.flow.parameter, value=lam, alpha=alpha, omega=omega,
            period=p, multipliers=P.info.mu.copy(), state=P.info.cycle[0].copy(),
            cycle=P.info.cycle.copy(), cycle_half=P.info.half.copy(), branch=-1,
            neighbours=(float(a_lam), float(b_lam)),
            neighbour_multipliers=np.array([mu_a, mu_b]), located=True,
            n_simulate=self.flow.calls - calls0, detail=detail,
            has_mirror=not P.info.symmetric)

    def _bisect(self, a, c, form, p, same_side):
        """Bisection along ``a.y + s c``, s in [0, 1], ``same_side(point or None)``."""
        n = unit(c)
        lo, hi, Plo = 0.0, 1.0, a
        Phi = None
        for _ in range(60):
            if (hi - lo) * abs(c[2]) <= 0.1 * self.param_tol and hi - lo < 1e-3:
                break
            sv = 0.5 * (lo + hi)
            try:
                Q = self._chord_point(a, c, n, sv, form, p)
            except LocateFailed:
                Q = None
            if Q is not None and same_side(Q):
                lo, Plo = sv, Q
            else:
                hi, Phi = sv, Q
        return Plo, Phi, (hi - lo) * abs(c[2])

    def refine_edge(self, P, direction, p):
        """Where the orbit through ``P`` (with its impact count) stops existing, towards
        ``direction`` (+-1) in the parameter: damped Newton at fixed parameter values, doubling
        the distance from ``P`` until it fails, then bisection to ``param_tol / 10``.

        Near a grazing the corrector's undamped steps fail some ``1e-8`` short of it; the
        damped Newton that keeps the orbit's impact count, from the branch's tangent predictor,
        gets within ``1e-9`` (a start from the last orbit itself, without the predictor, can
        already have crossed, and Newton then finds the other orbit that meets it there).
        Returns ``(point, bracket width)``; ``(P, inf)`` if no end is found within ``1e-3``.
        """
        s = self.s
        if direction == 0:
            return P, math.inf

        def slope(lam0, x0, F0, M0):
            """``dx/dlambda`` along the branch: ``-(M - I)^-1 F_lambda`` (``F_lambda`` by a
            difference backwards, away from the grazing)."""
            h = -direction * 1e-7 * max(1.0, abs(lam0))
            e = s.full(x0, lam0 + h, p, P.j)
            if not e.ok or e.nimp != P.info.nimp:
                return np.zeros(2)
            try:
                return -np.linalg.solve(M0 - np.eye(2), (e.F - F0) / h)
            except np.linalg.LinAlgError:
                return np.zeros(2)

        def trial(lam, base):
            """Newton at ``lam`` from the tangent predictor of the last orbit found, the orbit
            with ``P``'s impact count only (a start or step with another count fails)."""
            if not self.flow.valid(lam):
                return None
            lam0, x0, dx = base
            try:
                ev, _ = s.newton(x0 + dx * (lam - lam0), lam, p, P.j, P.info.scale,
                                 max_iter=20, count=P.info.nimp)
            except OrbitRefused:
                return None
            # an orbit, not a point stuck against the grazing: beyond it, Newton converges to
            # within the tolerance (which grows with |M|) on the side without the impact, but
            # cannot take the residual down to round-off, as it does on an orbit (Newton's
            # point is kept: the polished one only tells the two apart)
            polished = s.polish(ev, lam, p, P.j)
            return ev if float(np.abs(polished.F).max()) <= 0.01 * s.tol_for(polished) \
                else None

        def based(lam, ev):
            return lam, ev.x, slope(lam, ev.x, ev.F, ev.M)

        lo, ev_lo, hi = float(P.y[2]), None, None
        base = (lo, P.y[:2], slope(lo, P.y[:2], np.zeros(2), P.info.M))
        d = self.param_tol
        while d <= 1e-3:
            lam = lo + direction * d
            ev = trial(lam, base)
            if ev is None:
                hi = lam
                break
            lo, ev_lo = lam, ev
            base = based(lo, ev)
            d *= 2.0
        if hi is None:
            return P, math.inf
        while abs(hi - lo) > 0.1 * self.param_tol:
            mid = 0.5 * (lo + hi)
            ev = trial(mid, base)
            if ev is None:
                hi = mid
            else:
                lo, ev_lo = mid, ev
                base = based(lo, ev)
        if ev_lo is None:
            return P, abs(hi - lo)
        info = s.analyse(ev_lo.r, lo, p, P.j)
        return BranchPoint(np.r_[ev_lo.x, lo], P.j, P.j, info), abs(hi - lo)

    def locate_grazing(self, a, b, form, p, bifs):
        """The impact count changes between a and b: bisection on the count."""
        calls0 = self.flow.calls
        Plo, Phi, width = self._bisect(a, b.y - a.y, form, p,
                                       lambda Q: Q.info.nimp == a.info.nimp)
        direction = np.sign(b.y[2] - a.y[2])
        Q, w2 = self.refine_edge(Plo, direction, p)
        if w2 < math.inf:
            Plo, width = Q, w2
        hop = self.hop(Plo, p, direction) if a.info.nimp > b.info.nimp else None
        if hop is not None:
            Plo, width = hop
        if Plo is a:
            Plo = None
        P = Plo if Plo is not None else a
        ms = P.info.min_speed
        kind = (f"an impact with |theta'-| -> 0 (now {ms:.2g} of max |theta'|)"
                if a.info.nimp > b.info.nimp else
                f"|theta| touches 0 without impact (now {P.info.near_miss:.2g} of max |theta|)")
        if hop is not None:
            kind = _HOP
        detail = (f"impacts per cycle {a.info.nimp} -> {b.info.nimp}: {kind}; bracket "
                  f"{width:.1g} wide")
        bifs.append(self._graze_bif(P, a.y[2], b.y[2], a.info.mu, b.info.mu, p, detail,
                                    calls0))
        return Plo

    def graze_at(self, a, t, p, bifs):
        """The corrector fails next to a grazing: the orbit is followed to where it ends."""
        calls0 = self.flow.calls
        nm, ms = a.info.near_miss, a.info.min_speed
        what = (f"|theta| turns back short of 0 without impact (by {nm:.2g} of its largest "
                "value at the last point continued)" if nm <= ms else
                f"an impact with |theta'-| -> 0 ({ms:.2g} of the largest |theta'| at the last "
                "point continued)")
        Q, width = self.refine_edge(a, np.sign(t[2]), p)
        hop = self.hop(Q, p, np.sign(t[2]))
        if hop is not None:
            Q, width = hop
            what = _HOP
        detail = f"{what}; located to a bracket {width:.1g} wide"
        mu_b = np.full(2, np.nan, complex)
        bifs.append(self._graze_bif(Q, a.y[2], Q.y[2] + np.sign(t[2]) * width, a.info.mu,
                                    mu_b, p, detail, calls0))
        return None if Q is a else Q

    def hop(self, Q, p, direction):
        """At the end of an orbit whose excursion touches down twice at low speed and comes
        back, the orbit next to it without those two impacts, followed to where it ends: the
        grazing where the two meet, located from the side where the map is smooth. Returns
        ``(point, bracket width)``, or ``None``."""
        r = Q.info.run
        if r is None or not slow_pair(r) or Q.info.nimp < 2:
            return None
        s, lam, j = self.s, float(Q.y[2]), Q.j
        target = Q.info.nimp - 2
        depth = Depth(self.flow.block, self.flow, "impact", p, False)

        def evaluate(x):
            e = s.full(x, lam, p, j)
            if not e.ok:
                return False, None, None
            if e.nimp == target and depth(e.r, lam, j) is not None:
                return True, None, e
            return False, depth.deficit(e.r, lam, j) if e.nimp > target else None, None

        x0 = np.array(Q.y[:2], float)
        _, d0, _ = evaluate(x0)
        if d0 is None:
            return None
        g, got = deficit_gradient(evaluate, x0, d0)
        if got is None and g is not None:
            got = push_onto(evaluate, x0, -g / float(g @ g), d0)
        if got is None:
            return None
        try:
            ev, _ = s.newton(got.x, lam, p, j, Q.info.scale, max_iter=30, count=target)
        except OrbitRefused:
            return None
        P = BranchPoint(np.r_[ev.x, lam], j, j, s.analyse(ev.r, lam, p, j))
        end, width = self.refine_edge(P, direction, p)
        return None if width == math.inf else (end, width)

    def locate_end(self, a, t, ds_fail, form, p, why, bifs):
        """The branch ends by overturning or rest: bisection on where it stops existing."""
        calls0 = self.flow.calls
        Plo, Phi, width = self._bisect(a, ds_fail * t, form, p, lambda Q: True)
        Q, w2 = self.refine_edge(Plo, np.sign(t[2]), p)
        if w2 < math.inf:
            Plo, width = Q, w2
        what = {"overturn": "max |theta| reaches theta_over (the orbit overturns)",
                "rest": "the orbit comes to rest",
                "passes_through_rest": "the orbit enters a rest phase (impact speeds -> 0)",
                "max_impacts": "impacts accumulate (impact bound)"}[why]
        hop = self.hop(Plo, p, np.sign(t[2])) if why in ("rest", "passes_through_rest") \
            else None
        if hop is not None:
            Plo, width = hop
            what = _HOP
        P = a if Plo is a else Plo
        detail = f"{what}; bracket {width:.1g} wide"
        mu_b = np.full(2, np.nan, complex)
        bifs.append(self._graze_bif(P, a.y[2], a.y[2] + ds_fail * t[2], a.info.mu, mu_b, p,
                                    detail, calls0))
        return None if Plo is a else Plo

