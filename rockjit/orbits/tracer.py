"""Follows one curve of an extended system in the forcing plane: the bordered Newton corrector,
the pseudo-arclength march, the codimension-two points met and why the curve ends
(:class:`Tracer`); and a curve's system assembled at its computational section. The choices
(steps, ends, what is watched for) are set out in :mod:`.curves`' docstring, "Continuation",
"Grazing" and "Codimension two".
"""

from __future__ import annotations

import math

import numpy as np

from .bifurcations import BranchPoint, unit
from .curve_types import Codim2Point
from .extended import Extended, PlaneFlow
from .grazing import Depth, deficit_gradient, push_onto
from .shooting import Solver
from .types import OrbitRefused

__all__: list[str] = []


# ---------------------------------------------------------------------------------------------
# the tracer: corrector, points, marching, codimension two, ends
# ---------------------------------------------------------------------------------------------

class _Failed(Exception):
    pass


class Tracer:
    """Follows one curve of the extended system."""

    def __init__(self, ext, box, settings, sym_tol):
        self.ext = ext
        self.s = ext.s
        self.flow = ext.flow
        self.N = self.s.N
        self.box = box  # (a0, a1, w0, w1)
        self.ds0, self.ds_min, self.ds_max = settings.ds0, settings.ds_min, settings.ds_max
        self.max_points = settings.max_points
        self.max_calls = settings.max_calls
        self.param_tol = settings.param_tol
        self.max_mu = settings.max_multiplier
        self.sym_tol = sym_tol
        self.codim2 = []
        self.grad = None  # the condition's gradient at the last Jacobian
        self.J = None  # the last Jacobian (the chord method's, from point to point)
        self.J_start = None

    # -- corrector ----------------------------------------------------------------------------
    def correct(self, y0, n, j, max_iter=12, max_jac=2):
        """Newton's method on ``G(y) = 0``, ``n . (y - y0) = 0``; ``(ok, y, eval, its, why)``.

        The Jacobian is the last point's (a chord method), updated by Broyden's rank-one
        formula in its differenced part and exactly in ``M - I``; a new one (at most
        ``max_jac``) where the residual falls by less than a factor 20. On a grazing curve the
        solution lies on the edge of the side the condition is defined on: each step aims at
        a depth of 0.3 times the tolerance, and a predictor or step off the side is pushed
        back onto it (:meth:`onto_side`) along the direction that raises the condition (the
        condition's gradient; the linear model's response to its target)."""
        ext = self.ext
        y = np.array(y0, float)
        c = float(n @ y)
        ev = ext(y, j)
        if not ev.ok and ext.depth is not None and self.grad is not None:
            # a predictor off the grazing condition's side: pushed up the condition's
            # gradient, onto it
            ev = self.onto_side(y, self.grad / float(self.grad @ self.grad), ev, j)
            y = ev.y if ev.ok else y
        if not ev.ok:
            return False, y, ev, 0, ev.reason
        J = self.J
        fresh = False
        n_jac = 0
        prev = math.inf
        dG = dy = None
        for it in range(max_iter):
            ft, gt = ext.tol(ev)
            h = float(n @ y) - c
            res = max(float(np.abs(ev.F).max()) / ft, abs(ev.g) / gt, abs(h) / 1e-13)
            if res <= 1.0 or (res <= 10.0 and it >= 3 and res > 0.5 * prev):
                self.J = J if J is not None else self.J  # (10: the round-off floor)
                return True, y, ev, it, None
            slow = res > 0.05 * prev
            if slow and fresh and it >= 3 and n_jac >= max_jac:
                break
            prev = res
            if J is None or (slow and (not fresh or n_jac < max_jac)):
                J = ext.jacobian(ev, j)
                fresh = True
                n_jac += 1
                if J is None:
                    return False, y, ev, it, "grazing"
                self.grad = J[2].copy()
            elif dG is not None:
                # Broyden's update of the differenced part, the exact part set again
                J = ext.refresh(J + np.outer(dG - J @ dy, dy) / float(dy @ dy), ev)
            A = np.vstack([J, n])
            # on a grazing curve, aim inside the side (a step off it is pushed back onto it,
            # along the direction in which the linear model raises the condition)
            target = 0.0 if ext.depth is None else 0.3 * gt
            try:
                dy = np.linalg.solve(A, -np.r_[ev.F, ev.g - target, h])
            except np.linalg.LinAlgError:
                return False, y, ev, it, "singular"
            if not np.all(np.isfinite(dy)):
                return False, y, ev, it, "singular"
            cap = 0.5 * max(float(np.abs(y[:2]).max()), 1e-3)
            big = float(np.abs(dy[:2]).max())
            if big > cap:
                dy *= cap / big
            e2 = ext(y + dy, j)
            if not e2.ok and ext.depth is not None:
                u = np.linalg.solve(A, np.r_[0.0, 0.0, 1.0, 0.0])
                e2 = self.onto_side(y + dy, u, e2, j, 3.0 * gt)
                if e2.ok:
                    dy = e2.y - y
            if not e2.ok:
                return False, y + dy, e2, it, e2.reason
            dG = e2.G - ev.G
            y, ev = e2.y, e2
        return False, y, None, max_iter, "no_convergence"

    def _trial(self, j):
        def evaluate(y):
            ev = self.ext(y, j)
            return ev.ok, ev.deficit, ev
        return evaluate

    def onto_side(self, y, u, ev, j, start=1e-11):
        """From ``y``, off a grazing condition's side (``ev`` its evaluation), along ``u``
        (raising the condition by one per unit), to just inside (:func:`.grazing.push_onto`).
        Returns the valid evaluation, or ``ev``."""
        got = push_onto(self._trial(j), y, u, ev.deficit, start)
        return ev if got is None else got

    def enter_side(self, y, j, ev):
        """From ``y`` off a grazing condition's side (``ev``), onto it at the same parameters:
        along the gradient of the estimated deficit in the state
        (:func:`.grazing.deficit_gradient`). ``None`` where no deficit is estimated."""
        if ev.deficit is None:
            return None
        g, got = deficit_gradient(self._trial(j), y, ev.deficit)
        if got is not None or g is None:
            return got
        return self.onto_side(y, -g / float(g @ g), ev, j)

    def point(self, y, j, ev):
        """A curve point from a converged corrector."""
        info = self.s.analyse(ev.r, (y[2], y[3]), self.ext.p, j)
        P = BranchPoint(np.array(y, float), j, j, info)
        P.g, P.res = float(ev.g), float(np.abs(ev.F).max())
        return P

    def tangent(self, P):
        """The curve's unit tangent at ``P`` (null vector of ``dG/dy``), ``omega`` rising."""
        ev = self.ext(P.y, P.j)
        if not ev.ok:
            return None
        J = self.ext.jacobian(ev, P.j)
        if J is None:
            return None
        self.grad = J[2].copy()
        self.J_start = J
        t = np.linalg.svd(J)[2][-1]
        if not np.all(np.isfinite(t)):
            return None
        return t if t[3] >= 0 else -t

    # -- sections -----------------------------------------------------------------------------
    def move_section(self, a, b):
        cur, best, mbest = self.s.margins(b.info, b.j)
        if cur < 0.3 * mbest:
            for P in (a, b):
                P.y[:2] = self.s.shifted(P.info, (best - P.jt) % self.N)
                P.j = best
            self.J = None  # the state's coordinates changed

    def defect(self, P):
        """The symmetry (odd ``p``) or half-period (even ``p``) defect of a full-map orbit."""
        return float(np.abs(self.s.defect(P.info, self.ext.p, 0)).max()) / P.info.scale

    # -- marching -----------------------------------------------------------------------------
    def _edge(self, a, t, ds):
        """The predictor, clipped at the chart's edge: ``(y_pred, n, at_edge)``."""
        a0, a1, w0, w1 = self.box
        y = a.y + ds * t
        first, which = None, None
        for idx, lo, hi in ((2, a0, a1), (3, w0, w1)):
            if y[idx] > hi and t[idx] > 0:
                sb = (hi - a.y[idx]) / t[idx]
            elif y[idx] < lo and t[idx] < 0:
                sb = (lo - a.y[idx]) / t[idx]
            else:
                continue
            if first is None or sb < first:
                first, which = sb, (idx, hi if t[idx] > 0 else lo)
        if first is None:
            return y, t, False
        yb = a.y + max(first, 0.0) * t
        yb[which[0]] = which[1]
        n = np.zeros(4)
        n[which[0]] = 1.0
        return yb, n, True

    def march(self, start, t):
        """Follow the curve from ``start`` along ``t``; returns ``(points, end reason)``."""
        pts = []
        a = start
        ds = self.ds0
        self.J = self.J_start  # the seed's Jacobian (the other direction's last is far away)
        self.grad = None if self.J is None else self.J[2].copy()
        t = unit(np.asarray(t, float))
        fail_ds, why = None, None
        ctype = self.ext.type
        while True:
            if len(pts) >= self.max_points:
                return pts, "max_points"
            if self.flow.calls > self.max_calls:
                return pts, "budget"
            y_pred, n, at_edge = self._edge(a, t, ds)
            ok, y, ev, iters, why = self.correct(y_pred, n, a.j)
            b = self.point(y, a.j, ev) if ok else None
            if b is not None and b.info.nimp != a.info.nimp:
                end = self.end_by_count(a, b)
                if end is not None:
                    pts.append(end)
                self.ends_on_grazing(pts[-1] if pts else a, len(pts) - 1 + 1)
                return pts, "grazing"
            if b is not None and self.ext.form == "full" and self.ext.depth is None:
                da, db = self.defect(a), self.defect(b)
                if db <= 10 * self.sym_tol or (db < 0.2 * da and db < 1e-2 and ds <= 10 *
                                               self.ds_min):
                    self.branch_end(b, len(pts))
                    return pts, "branch_point"
            if b is None:
                fail_ds = ds
                ds *= 0.5
                if ds < self.ds_min:
                    return pts, self.end_by_failure(a, t, fail_ds, why, pts)
                continue
            b.iters = iters
            self.watch(a, b, len(pts), ctype)
            pts.append(b)
            if float(np.abs(b.info.mu).max()) > self.max_mu:
                return pts, "unstable"
            if at_edge:
                return pts, "range"
            if len(pts) > 10 and np.linalg.norm(b.y - start.y) < ds and \
                    abs(b.y[2] - start.y[2]) + abs(b.y[3] - start.y[3]) < ds:
                return pts, "closed"
            if iters <= 6:
                ds = min(1.3 * ds, self.ds_max)
            self.move_section(a, b)
            sec = b.y - a.y
            if np.linalg.norm(sec) > 0:
                t_new = unit(sec)
                if ctype == "fold" and len(pts) >= 2:
                    self.watch_cusp(a, b, t, t_new, len(pts) - 1)
                t = t_new
            if a is not start:
                a.info.traj = None
                a.info.run = None
            a = b

    # -- codimension two ----------------------------------------------------------------------
    def watch(self, a, b, index, ctype):
        """Sign changes of the multiplier test functions between ``a`` and ``b``."""
        pa, pb = a.info.psi, b.info.psi
        names = {"fold": {1: "fold_flip", 2: "resonance_1_1"},
                 "symmetry_breaking": {1: "fold_flip", 2: "resonance_1_1"},
                 "period_doubling": {0: "fold_flip", 2: "resonance_1_2"},
                 "grazing": {0: "grazing_fold", 1: "grazing_period_doubling"}}[ctype]
        for idx, name in names.items():
            if pa[idx] * pb[idx] < 0:
                Q, located = self.locate(a, b, idx)
                if name == "grazing_fold" and self.ext.form == "sym":
                    ja, jb = self._half_det(a), self._half_det(b)
                    if not (ja is not None and jb is not None and ja * jb < 0):
                        name = "grazing_symmetry_breaking"
                self.add(name, Q, index, located,
                         "located by Brent's method on the chord" if located else
                         "the nearer curve point (the bracketing solve failed)")

    def _half_det(self, P):
        ev = self.s.sym(P.y[:2], (P.y[2], P.y[3]), self.ext.p, P.j)
        if not ev.ok:
            return None
        J = self.s.jac_x("sym", ev, self.ext.p, P.j)
        return None if J is None else float(np.linalg.det(J))

    def locate(self, a, b, idx):
        """Brent's method on ``psi[idx]`` along the chord from ``a`` to ``b``."""
        from scipy.optimize import brentq
        c = b.y - a.y
        n = unit(c)
        cache = {0.0: a, 1.0: b}

        def P(sv):
            if sv not in cache:
                ok, y, ev, _, _ = self.correct(a.y + sv * c, n, a.j)
                if not ok:
                    raise _Failed()
                cache[sv] = self.point(y, a.j, ev)
            return cache[sv]

        span = max(float(np.hypot(c[2], c[3])), 1e-300)
        try:
            sv = brentq(lambda u: P(u).info.psi[idx], 0.0, 1.0,
                        xtol=max(1e-13, 0.1 * self.param_tol / span), maxiter=100)
            return P(sv), True
        except (_Failed, RuntimeError, ValueError):
            fa, fb = a.info.psi[idx], b.info.psi[idx]
            return (a if abs(fa) < abs(fb) else b), False

    def watch_cusp(self, a, b, t_old, t_new, index):
        """A fold curve whose projection on the plane turns back: a cusp between a and b."""
        po, pn = t_old[2:], t_new[2:]
        if float(po @ pn) < 0 and np.linalg.norm(po) > 0 and np.linalg.norm(pn) > 0:
            last = next((c for c in reversed(self.codim2) if c.type == "cusp"), None)
            if last is not None and math.hypot(last.alpha - b.y[2],
                                               last.omega - b.y[3]) < 1e-3:
                return  # the same cusp (near it the planar tangent is small and noisy)
            self.add("cusp", b, index, False,
                     "the curve's projection on the plane turns back between two points")

    def add(self, name, Q, index, located, detail):
        self.codim2.append(Codim2Point(
            type=name, alpha=float(Q.y[2]), omega=float(Q.y[3]),
            state=Q.info.cycle[0].copy(), multipliers=Q.info.mu.copy(), index=int(index),
            located=located, detail=detail))

    # -- ends ---------------------------------------------------------------------------------
    def _bisect(self, a, c, keep):
        """Bisection along ``a.y + s c`` (s in [0, 1]) for the last corrected point with
        ``keep(point)``; returns that point (``a`` if none)."""
        n = unit(c)
        lo, hi, Plo = 0.0, 1.0, a
        span = max(float(np.hypot(c[2], c[3])), 1e-300)
        for _ in range(50):
            if (hi - lo) * span <= 0.1 * self.param_tol:
                break
            sv = 0.5 * (lo + hi)
            ok, y, ev, _, _ = self.correct(a.y + sv * c, n, a.j)
            Q = self.point(y, a.j, ev) if ok else None
            if Q is not None and keep(Q):
                lo, Plo = sv, Q
            else:
                hi = sv
        return Plo

    def end_by_count(self, a, b):
        """The impact count changes from ``a`` to ``b``: the last point with ``a``'s count."""
        P = self._bisect(a, b.y - a.y, lambda Q: Q.info.nimp == a.info.nimp)
        return None if P is a else P

    def ends_on_grazing(self, P, index):
        if self.ext.depth is not None:
            self.add("double_grazing", P, index, False,
                     f"another excursion of the grazing orbit grazes (near miss "
                     f"{P.info.near_miss:.2g}, slowest impact {P.info.min_speed:.2g} of the "
                     f"orbit's size at the last point continued)")
            return
        self.add(f"grazing_{self.ext.type}", P, index, True,
                 f"the curve meets a grazing curve: impacts per cycle change from "
                 f"{P.info.nimp} (last point continued); min impact speed "
                 f"{P.info.min_speed:.2g}, near miss {P.info.near_miss:.2g} of the orbit's size")

    def end_by_failure(self, a, t, ds_fail, why, pts):
        """The corrector fails at the smallest step: why the curve ends there."""
        if why in ("overturn", "rest", "passes_through_rest", "max_impacts"):
            P = self._bisect(a, ds_fail * t, lambda Q: True)
            if P is not a:
                pts.append(P)
            reason = "overturn" if why == "overturn" else "rest" if why != "max_impacts" \
                else "no_convergence"
            if self.ext.depth is None and reason == "overturn":
                self.add(f"grazing_{self.ext.type}", P, len(pts) - 1, True,
                         "the curve meets the overturn grazing: max |theta| reaches "
                         "theta_over")
            return reason
        if self.ext.depth is None and min(a.info.near_miss, a.info.min_speed) < 1e-3:
            self.ends_on_grazing(a, len(pts) - 1)
            return "grazing"
        return "no_convergence"

    def branch_end(self, P, index):
        p = self.ext.p
        if self.ext.type == "fold":
            name = "degenerate_pitchfork" if p % 2 else "degenerate_flip"
            self.add(name, P, index, False,
                     "the fold curve ends where its orbit becomes "
                     + ("symmetric" if p % 2 else f"of period {p // 2}"))


# ---------------------------------------------------------------------------------------------
# a curve's system: its computational section, its flow, solver, extended system and tracer
# ---------------------------------------------------------------------------------------------

def _section(solver, x, lam, p):
    """The computational section for a seed at ``x``: ``(j, x at that section, run)``."""
    ev = solver.full(x, lam, p, 0)
    if not ev.ok:
        raise OrbitRefused(ev.reason, "at the seed")
    cur, best, mbest = solver.margins_of(ev.r.impacts[:, 0], solver.flow.period(lam), 0)
    if cur < 0.3 * mbest:
        return best, ev.r.trajectory[best, 1:3].copy()
    return 0, np.array(x, float)


def _system(block, ctype, p, symmetric, kind, count, phase, n_steps, shooting, box, settings,
            flow=None, solver=None):
    """The flow, solver, extended system and tracer of a curve."""
    flow = PlaneFlow(block, phase, n_steps, shooting) if flow is None else flow
    solver = Solver(flow, shooting) if solver is None else solver
    depth = None if kind is None else Depth(block, flow, kind, p, symmetric)
    ext = Extended(solver, ctype, p, "sym" if symmetric else "full", count, depth)
    return flow, solver, ext, Tracer(ext, box, settings, shooting.sym_tol)
