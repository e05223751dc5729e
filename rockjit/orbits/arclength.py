"""Continuation of periodic orbits: branches followed by pseudo-arclength from seeds, their
bifurcations located (:mod:`.bifurcations`) and the branches born there followed too; and the
branches of a sweep's periodic attractors, the sweep run first when none is given.

Definitions and choices
-----------------------
Continuation
    Pseudo-arclength (Keller 1977; Seydel 2010 ch. 4; Doedel et al. 1991): unknowns
    ``y = (theta, theta', lambda)``, secant predictor, Newton corrector on the bordered system
    ``[F_x F_lambda; t^T]`` with ``F_lambda`` by a forward difference, step grown by 1.3 after a
    corrector of at most 3 iterations and halved after a failure. A step whose orbit has a
    different number of impacts per cycle brackets a grazing, which is then located
    (:mod:`.bifurcations`) and ends the branch. Near a grazing from the side without the extra
    impact the corrector fails before the count changes: when the step has shrunk to ``ds_min``
    and the last orbit turns back within ``1e-3`` of its size from ``theta = 0`` (or hits it at
    a speed that small), the orbit is followed at fixed parameter values to where it stops
    existing. Overturning and rest end a branch likewise. A branch also ends at the range's
    end, at a branch point (a doubled or asymmetric branch folding back onto the orbit it was
    born from, which is then seeded too), on joining a branch already computed (or its mirror
    image: cycles compared by :func:`rockjit.grids.cycles.cycle_distance`), or on closing a
    loop. A bifurcation met again on a stretch that retraces a branch already followed (a seed
    next to a fold of that branch, before it joins it) is reported once.
Seeds
    A seed is solved by shooting (:mod:`.shooting`) and followed both ways unless its orbit lies
    on a branch already followed; a sweep seeds one branch per distinct periodic attractor.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..grids.cycles import cycle_distance
from ..entry import entry_point
from ..grids import plan as gp
from ..grids import sweep_grid
from ..settings import Execution
from ..validate import integer, pair, real
from .bifurcations import BranchPoint, Locator, unit
from .shooting import (N_ORBIT, Flow, Solver, check_block, check_forcing, check_n_steps,
                       check_shooting, check_state, shoot)
from .sweep_seeds import seeding_sweep, sweep_section, sweep_seeds
from .types import (Branch, Continuation, ContinuationSettings, OrbitRefused, PeriodicOrbit,
                    Shooting, settings_record)

__all__ = ["OrbitsPlan", "continuation", "continue_branches", "orbits_of_sweep", "run"]


def _range(name, rng, lo):
    a, b = pair(name, rng, lo)
    if b <= a:
        raise ValueError(f"{name} must satisfy start < end (got {a:g}, {b:g})")
    return a, b


def _settings(settings):
    settings = ContinuationSettings() if settings is None else settings
    if not isinstance(settings, ContinuationSettings):
        raise ValueError(f"settings must be a rockjit.orbits.ContinuationSettings "
                         f"(got {type(settings).__name__})")
    return settings


@dataclass
class _Leg:
    """One direction of a branch as it is followed: its start, form (``"full"`` or ``"sym"``)
    and period, the points kept, and the bifurcations and branch switches met on the way."""

    start: BranchPoint
    form: str
    p: int
    bifs: list
    requests: list
    pts: list = field(default_factory=list)


class Continuer(Locator):
    """Follows branches from seeds, locates bifurcations, switches branches."""

    def __init__(self, solver, bounds, settings):
        self.s = solver
        self.flow = solver.flow
        self.N = solver.N
        self.lo, self.hi = bounds
        self.ds0, self.ds_min, self.ds_max = settings.ds0, settings.ds_min, settings.ds_max
        self.max_points = settings.max_points
        self.max_period = settings.max_period
        self.switching = settings.switch
        self.join_tol = settings.join_tol
        self.max_calls = settings.max_calls
        self.param_tol = settings.param_tol
        self.end_graze = 1e-3
        self.branches = []
        self.bifs = []
        self.seeds_tried = 0

    # -- the branch around a point -------------------------------------------------------------
    def defect(self, P, p, j):
        return self.s.defect(P.info, p, (j - P.jt) % self.N)

    def tangent(self, P, form, p):
        """The branch's unit tangent at ``P`` (null vector of ``[F_x F_lambda]``)."""
        ev = self.s.residual(form, P.y[:2], P.y[2], p, P.j)
        if not ev.ok:
            return None
        Jx = self.s.jac_x(form, ev, p, P.j)
        Jl = self.s.jac_lam(form, ev, p, P.j)
        if Jx is None or Jl is None:
            return None
        t = np.cross(np.r_[Jx[0], Jl[0]], np.r_[Jx[1], Jl[1]])
        if not np.all(np.isfinite(t)) or np.linalg.norm(t) == 0:
            return None
        t = unit(t)
        return t if t[2] >= 0 else -t

    # -- known branches -----------------------------------------------------------------------
    def known(self, info, lam, p, symmetric, tol=None):
        """Index of a finished branch (or its mirror) through this orbit, else ``None``."""
        return self.known_cycle(info.cycle, info.scale, lam, p, symmetric,
                                self.join_tol if tol is None else tol)

    def known_cycle(self, cycle, scale, lam, p, symmetric, tol):
        """As :meth:`known` for a bare cycle; ``symmetric=None`` matches either kind."""
        tol = tol * scale
        for bi, br in enumerate(self.branches):
            if br.period != p or (symmetric is not None and br.symmetric != symmetric):
                continue
            v = br.value
            ks = np.nonzero((v[:-1] - lam) * (v[1:] - lam) <= 0)[0]
            cycles = (br.cycle,) if br.symmetric else (br.cycle, br.mirror_cycle)
            n = v.shape[0]
            for k in ks:
                # interpolation within the segment, and extrapolation from the segments on
                # either side (the sampled point jumps where an impact crosses t = 0)
                for i0, i1 in ((k, k + 1), (k - 1, k), (k + 1, k + 2)):
                    if i0 < 0 or i1 >= n:
                        continue
                    dv = v[i1] - v[i0]
                    w = (lam - v[i0]) / dv if dv != 0 else 0.5
                    for cyc in cycles:
                        ci = (1 - w) * cyc[i0] + w * cyc[i1]
                        if cycle_distance(ci, cycle) <= tol:
                            return bi
        return None

    # -- one direction ------------------------------------------------------------------------
    def march(self, start, t, form, p, bifs, requests):
        """Follow the branch from ``start`` along ``t``; returns ``(points, end reason)``."""
        leg = _Leg(start, form, p, bifs, requests)
        pts = leg.pts
        a = BranchPoint(start.y.copy(), start.j, start.jt, start.info)
        ds = self.ds0
        t = unit(np.asarray(t, float))
        while True:
            if len(pts) >= self.max_points:
                return pts, "max_points"
            if self.flow.calls > self.max_calls:
                return pts, "budget"
            y_pred, n, at_end = self.predict(a, t, ds)
            ok, y, ev, iters, why = self.s.correct(y_pred, n, form, p, a.j)
            b = self.point(y, a.j, form, p, ev) if ok else None
            if b is None:
                why = why or "passes_through_rest"
                fail_ds = ds
                ds *= 0.5
                if ds < self.ds_min:
                    return pts, self.end_after_failure(a, t, fail_ds, why, leg)
                continue
            b.iters = iters
            end = self.end_before(a, b, leg)
            if end is None:
                end = self.end_after(a, b, ds, at_end, leg)
            if end is not None:
                return pts, end
            if iters <= 3:
                ds = min(1.3 * ds, self.ds_max)
            self.keep_section(a, b)
            sec = b.y - a.y
            if np.linalg.norm(sec) > 0:
                t = unit(sec)
            if a.info is not start.info:
                a.info.traj = None  # keep memory bounded: only the last two are needed
                a.info.run = None
            a = b

    def predict(self, a, t, ds):
        """The secant predictor from ``a``, cut at the range's end: ``(y, the corrector's
        normal, whether it is at the end)``."""
        y_pred = a.y + ds * t
        if not self.lo <= y_pred[2] <= self.hi and abs(t[2]) > 1e-12:
            bound = self.hi if y_pred[2] > self.hi else self.lo
            sb = (bound - a.y[2]) / t[2]
            if 0 <= sb <= ds:
                y_pred = a.y + sb * t
                y_pred[2] = bound
                return y_pred, np.array([0.0, 0.0, 1.0]), True
        return y_pred, t, False

    def end_after_failure(self, a, t, fail_ds, why, leg):
        """Why a branch ends where the corrector fails at the smallest step from ``a``; the
        point where it ends, when located, is kept."""
        form, p, bifs, pts = leg.form, leg.p, leg.bifs, leg.pts
        if why in ("overturn", "rest", "passes_through_rest", "max_impacts"):
            last = self.locate_end(a, t, fail_ds, form, p, why, bifs)
            if last is not None:
                pts.append(last)
        elif min(a.info.near_miss, a.info.min_speed) < self.end_graze:
            # the corrector fails next to a grazing (the map's derivative is singular
            # there): follow the orbit to where it ends
            last = self.graze_at(a, t, p, bifs)
            if last is not None:
                pts.append(last)
            return "grazing"
        return why

    def end_before(self, a, b, leg):
        """The end of a branch found on the step from ``a`` to ``b``, ``b`` not kept: a
        grazing (the point where it ends kept) or a branch point; else ``None``."""
        form, p = leg.form, leg.p
        if b.info.nimp != a.info.nimp:
            last = self.locate_grazing(a, b, form, p, leg.bifs)
            if last is not None:
                leg.pts.append(last)
            return "grazing"
        if form == "full":
            # a doubled (or asymmetric) branch folding back onto its parent orbit
            da = self.defect(a, p, a.j)
            db = self.defect(b, p, a.j)
            if float(da @ db) < 0 or float(np.abs(db).max()) <= \
                    10 * self.s.sym_tol * b.info.scale:
                return "branch_point"
        return None

    def end_after(self, a, b, ds, at_end, leg):
        """Keep ``b`` (the bifurcations between ``a`` and it detected); the branch's end there
        (it joins a known branch, reaches the range's end or closes), else ``None``."""
        start, pts = leg.start, leg.pts
        joined = self.known(b.info, b.y[2], leg.p, leg.form == "sym")
        self.detect(a, b, leg.form, leg.p, leg.bifs, leg.requests)
        pts.append(b)
        if joined is not None:
            return "joins"
        if at_end:
            return "range"
        if len(pts) > 10 and abs(b.y[2] - start.y[2]) < ds and cycle_distance(
                b.info.cycle, start.info.cycle) <= self.join_tol * b.info.scale:
            return "closed"
        return None

    def keep_section(self, a, b):
        """Move the section of ``a`` and ``b`` when an impact comes near the sampling
        instant."""
        cur, best, mbest = self.s.margins(b.info, b.j)
        if cur < 0.3 * mbest:
            for P in (a, b):
                P.y[:2] = self.s.shifted(P.info, (best - P.jt) % self.N)
                P.j = best

    # -- branches -----------------------------------------------------------------------------
    def finish(self, pts, ends, form, p, origin, parent, bifs):
        v = np.array([P.y[2] for P in pts])
        al, om = np.array([self.flow.params(x) for x in v]).T.reshape(2, -1)
        br = Branch(
            parameter=self.flow.parameter, period=p, symmetric=form == "sym", value=v,
            alpha=al, omega=om, cycle=np.array([P.info.cycle for P in pts]),
            cycle_half=np.array([P.info.half for P in pts]),
            multipliers=np.array([P.info.mu for P in pts]),
            stable=np.array([P.info.stable for P in pts]),
            impacts=np.array([P.info.nimp for P in pts], np.int64),
            symmetric_points=np.array([P.info.symmetric for P in pts]),
            t_next_impact=np.array([P.info.t_next for P in pts]),
            t_next_impact_half=np.array([P.info.t_next_half for P in pts]), ends=tuple(ends),
            origin=origin, parent=parent)
        idx = len(self.branches)
        self.branches.append(br)
        for bf in bifs:
            if self.reported(bf):
                continue
            bf.branch = idx
            self.bifs.append(bf)
        return idx

    def reported(self, bf):
        """Whether ``bf`` was located already, on a branch followed before.

        A seed whose orbit lies close to a fold of a branch already followed can escape
        :meth:`known` (the branch's points, linear in the parameter between them, are far from
        its orbit where the branch turns) and be followed again until it joins that branch,
        meeting the same bifurcations on the way: those are reported once. The same one is of
        the same type and period, at a parameter value within ``100 param_tol`` (or inside the
        other's bracket when either was not located) and at the same orbit, or its mirror
        image, within ``join_tol`` of its size (any cyclic shift).
        """
        scale = max(float(np.abs(bf.cycle).max()), 1e-12)
        for other in self.bifs:
            if other.type != bf.type or other.period != bf.period:
                continue
            if bf.located and other.located:
                near = abs(other.value - bf.value) <= 100 * self.param_tol * max(
                    1.0, abs(bf.value))
            else:
                near = any(min(o.neighbours) <= v <= max(o.neighbours)
                           for o, v in ((other, bf.value), (bf, other.value)))
            if not near:
                continue
            d = min(cycle_distance(other.cycle, bf.cycle),
                    cycle_distance(-other.cycle_half, bf.cycle))
            if d <= self.join_tol * scale:
                return True
        return False

    def follow_seed(self, lam, x, p, origin):
        """Solve a seed; if it is new, follow its branch both ways. Returns the branch index."""
        self.seeds_tried += 1
        if not self.lo <= lam <= self.hi:
            return None
        x = np.asarray(x, float)
        if x.ndim == 2:
            # a sweep's cycle: a cheap look first, at a tolerance loose enough for its grid
            if self.known_cycle(x, max(float(np.abs(x).max()), 1e-12), lam, p, None,
                                10 * self.join_tol) is not None:
                return None
            x = x[0]
        try:
            info, xc, j, _, _ = shoot(self.s, x, lam, p)
        except OrbitRefused:
            return None
        if p % 2 == 0 and float(np.abs(self.s.defect(info, p, 0)).max()) <= \
                10 * self.s.sym_tol * info.scale:
            return self.follow_seed(lam, info.cycle[0], p // 2, origin)
        sym = bool(info.symmetric)
        if self.known(info, lam, p, sym) is not None:
            return None
        form = "sym" if sym else "full"
        start = BranchPoint(np.r_[xc, lam], j, j, info)
        t = self.tangent(start, form, p)
        if t is None:
            return None
        bifs, requests = [], []
        plus, end_p = self.march(start, t, form, p, bifs, requests)
        if end_p == "closed":
            minus, end_m = [], "closed"
        else:
            minus, end_m = self.march(start, -t, form, p, bifs, requests)
        pts = minus[::-1] + [start] + plus
        idx = self.finish(pts, (end_m, end_p), form, p, origin, None, bifs)
        self.run_requests(requests, idx)
        # a seeded branch that folds back onto the orbit it was born from: follow that one too
        for end, P in ((end_m, pts[0]), (end_p, pts[-1])):
            if end == "branch_point":
                self.parent_seed(P, p, idx)
        return idx

    def parent_seed(self, P, p, idx):
        """Seed the orbit a branch point leads to: the symmetric one (odd ``p``) or the one of
        half the period (even ``p``), from the symmetrised (averaged) end point."""
        c, h = P.info.cycle, P.info.half
        if p % 2:
            x, pp = 0.5 * (c[0] - h[(p - 1) // 2]), p
        else:
            x, pp = 0.5 * (c[0] + c[p // 2]), p // 2
        lam = float(P.y[2])
        self.follow_seed(lam, x, pp, f"parent of branch {idx} (branch point at "
                                     f"{self.flow.parameter} = {lam:.6g})")

    def run_requests(self, requests, parent):
        for bif, Q, p in requests:
            new = self.switch(bif, Q, p, parent)
            bif.new_branch = new

    def switch(self, bif, Q, p, parent):
        """Onto the branch born at a period doubling (``2p``) or symmetry breaking (``p``)."""
        pd = bif.type == "period_doubling"
        pn = 2 * p if pd else p
        if pn > self.max_period or self.flow.calls > self.max_calls:
            return None
        w, V = np.linalg.eig(Q.info.M)
        i = int(np.argmin(np.abs(w - (-1.0 if pd else 1.0))))
        v = unit(np.real(V[:, i]))
        ystar = Q.y.copy()
        n = np.r_[v, 0.0]
        got = None
        for hrel in (1e-3, 1e-4, 3e-3, 1e-2):
            h = hrel * Q.info.scale
            ok, y, ev, _, _ = self.s.correct(np.r_[ystar[:2] + h * v, ystar[2]], n, "full",
                                             pn, Q.j, max_iter=12)
            R = self.point(y, Q.j, "full", pn, ev) if ok else None
            if R is None or not self.lo <= R.y[2] <= self.hi:
                continue
            d = self.s.defect(R.info, pn, 0)
            if float(np.abs(d).max()) <= 100 * self.s.sym_tol * R.info.scale:
                continue  # fell back onto the orbit it bifurcates from
            got = R
            break
        if got is None:
            bif.detail = (bif.detail + "; " if bif.detail else "") + "branch switching failed"
            return None
        known = self.known(got.info, got.y[2], pn, False)
        if known is not None:
            return known
        bifs, requests = [], []
        pts, end = self.march(got, got.y - ystar, "full", pn, bifs, requests)
        origin = f"{bif.type} of branch {parent} at {bif.parameter} = {bif.value:.10g}"
        idx = self.finish([got] + pts, ("branch_point", end), "full", pn, origin, parent,
                          bifs)
        self.run_requests(requests, idx)
        return idx


# ---------------------------------------------------------------------------------------------
# seeds, and one continuation from them
# ---------------------------------------------------------------------------------------------

def _seed_list(seeds, name):
    out = []
    for i, sd in enumerate(seeds):
        if isinstance(sd, PeriodicOrbit):
            out.append((None, sd.cycle, sd.period, sd))
            continue
        try:
            val, x, p = sd
        except (TypeError, ValueError):
            raise ValueError(f"{name}[{i}] must be (parameter value, state or cycle, p) or a "
                             f"PeriodicOrbit (got {sd!r})") from None
        p = integer(f"{name}[{i}] period", p, 1, 256)
        out.append((real(f"{name}[{i}] value", val), check_state(f"{name}[{i}] state", x, p),
                    p, None))
    return out


def _run(block, forcing, parameter, bounds, seeds, n_steps, shooting, settings, origin_fmt):
    """Follow every seed; ``forcing`` is the continuation's (without ``parameter``, at its
    phase)."""
    t0 = time.perf_counter()
    phase = forcing.phase
    fixed = "omega" if parameter == "alpha" else "alpha"
    flow = Flow(block, forcing, parameter, n_steps, phase, shooting)
    solver = Solver(flow, shooting)
    cont = Continuer(solver, bounds, settings)
    for val, x, p, orb in seeds:
        if orb is not None:
            if not math.isclose(orb.phase, phase, abs_tol=1e-12):
                raise ValueError(f"a PeriodicOrbit seed must be at the continuation's phase "
                                 f"{phase!r} (got {orb.phase!r})")
            if not math.isclose(getattr(orb, fixed), getattr(forcing, fixed)):
                raise ValueError(f"a PeriodicOrbit seed must be at the continuation's {fixed} "
                                 f"{getattr(forcing, fixed)!r} (got {getattr(orb, fixed)!r})")
            val = orb.alpha if parameter == "alpha" else orb.omega
            x = orb.cycle[0]
        cont.follow_seed(val, x, p, origin_fmt(val, p))
    branches, bifs = _within(cont.branches, cont.bifs, bounds)
    return Continuation(parameter=parameter, bounds=tuple(bounds), block=block,
                        forcing=forcing, phase=phase, n_steps=n_steps, branches=branches,
                        bifurcations=bifs, n_simulate=flow.calls,
                        wall_s=time.perf_counter() - t0, seeds_tried=cont.seeds_tried,
                        settings=settings_record(settings, shooting))


def _within(branches, bifs, bounds):
    """The branches' points and the bifurcations inside ``bounds`` (a branch switched onto at a
    bifurcation may be followed past the range before its march ends; what lies outside was
    not asked for)."""
    lo, hi = bounds
    tol = 1e-9 * max(1.0, abs(hi))
    kept = []
    for br in branches:
        m = (br.value >= lo - tol) & (br.value <= hi + tol)
        if not m.all():
            arrays = {f: getattr(br, f)[m] for f in ("value", "alpha", "omega", "cycle",
                                                     "cycle_half", "multipliers", "stable",
                                                     "impacts", "symmetric_points",
                                                     "t_next_impact", "t_next_impact_half")}
            ends = tuple("range" if not (lo - tol <= v <= hi + tol) else e
                         for v, e in zip((br.value[0], br.value[-1]), br.ends))
            br = Branch(parameter=br.parameter, period=br.period, symmetric=br.symmetric,
                        ends=ends, origin=br.origin, parent=br.parent, **arrays)
        kept.append(br)
    return kept, [b for b in bifs if lo - tol <= b.value <= hi + tol]


def continuation(block, forcing, seeds, *, parameter="alpha", bounds, n_steps=N_ORBIT,
                 shooting=None, settings=None) -> Continuation:
    """Follow the periodic orbits through given seeds as ``alpha`` or ``omega`` varies.

    Parameters
    ----------
    block : Block
        The block: slenderness, restitution law, damping.
    forcing : Harmonic
        The excitation (closed form) with the forcing parameter that stays fixed (``omega``
        when ``parameter`` is ``"alpha"``, ``alpha`` when it is ``"omega"``); a value of the
        continued one is not used (the seeds give it). Its phase is the stroboscopic
        section's: ``forcing.phase``, or that of its ``(r0, s0)``; neither: 0, i.e.
        ``(r0, s0) = (0, 1)``.
    seeds : sequence
        Each ``(value, state, p)``: the continuation parameter's value, ``(theta, theta')`` (or
        a ``(p, 2)`` cycle) at ``t = 0`` and the period; or a :class:`PeriodicOrbit` (at the same
        phase and fixed parameter).
    parameter : {"alpha", "omega"}
        The forcing parameter continued.
    bounds : (float, float)
        The parameter range; branches stop at its ends.
    n_steps : int
        Steps per forcing period (even, ``>= 8``), default :data:`N_ORBIT`.
    shooting : Shooting, optional
        Newton's tolerance, the symmetry and branch-point tolerance, the seeds' grazing
        thresholds, the runs' impact bound, overturning threshold and Zeno cut-off.
    settings : ContinuationSettings, optional
        The steps, the bounds on points, periods and runs, the joining and location
        tolerances, and whether branches born at bifurcations are followed.

    Returns
    -------
    Continuation
        Branches in the order found (switched branches right after their parent) and every
        located bifurcation inside ``bounds``.

    Raises
    ------
    ValueError
        For bad input, naming the parameter.

    Examples
    --------
    The study's asymmetric orbit (``h/b = 1``, ``omega = 1.3``) followed in ``alpha`` down to
    the symmetry-breaking pitchfork where it is born:

    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import ContinuationSettings, continuation
    >>> c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
    ...                  bounds=(0.77, 0.8), settings=ContinuationSettings(switch=False))
    >>> [(br.period, br.symmetric) for br in c.branches]
    [(1, False), (1, True)]
    >>> [(b.type, round(b.alpha, 4)) for b in c.bifurcations]
    [('symmetry_breaking', 0.7798)]
    """
    block = check_block(block)
    if parameter not in ("alpha", "omega"):
        raise ValueError(f"parameter must be 'alpha' or 'omega' (got {parameter!r})")
    fixed = "omega" if parameter == "alpha" else "alpha"
    forcing, phase = check_forcing(forcing, fixed, why=f"a continuation in {parameter}")
    bounds = _range("bounds", bounds, 0.0)
    if parameter == "omega" and bounds[0] <= 0:
        raise ValueError(f"bounds must be > 0 for omega (got {bounds})")
    n_steps = check_n_steps(n_steps)
    shooting = check_shooting(shooting)
    settings = _settings(settings)
    sl = _seed_list(seeds, "seeds")
    forcing = forcing.replace(**{parameter: None}, phase=phase, r0=None, s0=None)
    return _run(block, forcing, parameter, bounds, sl, n_steps, shooting, settings,
                lambda v, p: f"seed p={p} at {parameter} = {v:.6g}")


# ---------------------------------------------------------------------------------------------
# the branches of a sweep's attractors
# ---------------------------------------------------------------------------------------------

def continue_branches(block, forcing, alpha_range, seeds=None, sweep=None, *, n_steps=N_ORBIT,
                      shooting=None, settings=None, sweep_step=0.002) -> Continuation:
    """Every periodic branch of a sweep's attractors over ``alpha_range``, with bifurcations.

    Parameters
    ----------
    block : Block
        The block: slenderness, restitution law, damping.
    forcing : Harmonic
        The excitation with its ``omega`` and no ``alpha`` (the continuation's own). Its phase
        is the section's: with a sweep, the sweep's (a phase given must be that one); else the
        one given, or 0.
    alpha_range : (float, float)
        The amplitudes, ``start < end``.
    seeds : sequence, optional
        ``(alpha, state or cycle, p)`` at the forcing's phase, or :class:`PeriodicOrbit`
        (see :func:`continuation`).
    sweep : SweepResult, optional
        Seeds from every periodic cell (period up to ``settings.max_period``) of this sweep of
        the same block and ``omega``, at its forcing phase (that of its ``z0``). A cell whose
        orbit lies on a branch already followed (or its mirror image), within ``join_tol`` of
        the orbit's size and any cyclic shift, is skipped: each distinct attractor seeds one
        branch.
    n_steps : int
        Steps per forcing period (even, ``>= 8``), default :data:`N_ORBIT`.
    shooting : Shooting, optional
        As in :func:`continuation`; default :class:`Shooting`'s, with the sweep's
        ``theta_over`` and ``rest_speed`` when a sweep is given.
    settings : ContinuationSettings, optional
        As in :func:`continuation`.
    sweep_step : float
        With neither seeds nor a sweep, a sweep of this step over ``alpha_range`` from the
        study's ``z0`` (:func:`rockjit.sweep`, at the forcing's phase or the study's) is run
        first and seeds the branches.

    Returns
    -------
    Continuation
        Branches in the order found (seeds by period, then alpha; switched branches right
        after their parent) and every located bifurcation.

    Raises
    ------
    ValueError
        For bad input, naming the parameter.

    See Also
    --------
    orbits_of_sweep : the sweep and its branches as one entry point, with a plan that refuses
        bad input before any work and the sweep's execution (progress, Dask, chunk store).

    Examples
    --------
    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import ContinuationSettings, continue_branches
    >>> c = continue_branches(Block(hb=1), Harmonic(omega=1.3), (0.79, 0.81),
    ...                       sweep_step=0.01, settings=ContinuationSettings(switch=False))
    >>> [(br.period, br.symmetric, br.ends) for br in c.branches]
    [(1, False, ('range', 'range'))]
    >>> round(c.phase, 6)  # the sweep's: the study's forcing point
    -0.891245
    """
    block = check_block(block)
    forcing, phase = check_forcing(forcing, "omega", "-alpha",
                                   why="a continuation over alpha_range")
    a0, a1 = _range("alpha_range", alpha_range, 0.0)
    n_steps = check_n_steps(n_steps)
    shooting = None if shooting is None else check_shooting(shooting)
    settings = _settings(settings)
    sl = [] if seeds is None else _seed_list(seeds, "seeds")
    if seeds is None and sweep is None:
        sweep = seeding_sweep(block, forcing, (a0, a1), sweep_step, shooting)
    if sweep is not None:
        phase, shooting = sweep_section(sweep, block, forcing, phase, shooting)
        sl += sweep_seeds(sweep, settings.max_period)
    shooting = Shooting() if shooting is None else shooting
    forcing = forcing.replace(phase=phase, r0=None, s0=None)
    return _run(block, forcing, "alpha", (a0, a1), sl, n_steps, shooting, settings,
                lambda v, p: f"seed p={p} at alpha = {v:.6g}")


# ---------------------------------------------------------------------------------------------
# the sweep and its branches as one entry point (the command line's `rockjit orbits`)
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class OrbitsPlan:
    """A validated :func:`orbits_of_sweep`: the seeding sweep's plan and the continuation's
    inputs, from ``orbits_of_sweep.plan(...)``; :func:`run` executes it.

    Examples
    --------
    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import orbits_of_sweep
    >>> plan = orbits_of_sweep.plan(Block(hb=1), Harmonic(omega=1.3), (0.5, 1.0))
    >>> plan.sweep_plan.axes["alpha"].size, plan.n_steps, plan.settings.max_period
    (501, 384, 8)
    """

    sweep_plan: gp.GridPlan
    block: object
    forcing: object
    alpha_range: tuple
    n_steps: int
    shooting: Shooting
    settings: ContinuationSettings


def run(plan: OrbitsPlan, execution=None):
    """Execute an ``OrbitsPlan`` (``orbits_of_sweep.plan(...)``): the sweep, then the branches
    from its periodic attractors (:func:`rockjit.orbits.continue_branches`).

    Parameters
    ----------
    plan : OrbitsPlan
        From ``orbits_of_sweep.plan(...)``.
    execution : Execution, optional
        How the sweep runs (threads, chunks, a Dask cluster, a chunk store, progress); default
        in this process with all threads. It never changes a result.

    Returns
    -------
    (Continuation, SweepResult)

    Examples
    --------
    >>> from rockjit import Block, Execution, Harmonic
    >>> from rockjit.orbits import ContinuationSettings, arclength, orbits_of_sweep
    >>> plan = orbits_of_sweep.plan(Block(hb=1), Harmonic(omega=1.3), (0.79, 0.81),
    ...                             alpha_step=0.01, settings=ContinuationSettings(switch=False))
    >>> cont, sw = arclength.run(plan, Execution(progress=False))
    >>> len(cont.branches), round(cont.phase, 6)
    (1, -0.891245)
    """
    sw = gp.run(plan.sweep_plan, Execution() if execution is None else execution)
    cont = continue_branches(plan.block, plan.forcing, plan.alpha_range, sweep=sw,
                             n_steps=plan.n_steps, shooting=plan.shooting,
                             settings=plan.settings)
    return cont, sw


@entry_point(run)
def orbits_of_sweep(block, forcing, alpha_range, *, alpha_step=0.001, integration=None,
                    n_steps=N_ORBIT, shooting=None, settings=None, execution=None):
    """A sweep over ``alpha_range`` from the study's ``z0``, then every periodic branch of its
    attractors with their bifurcations (:func:`continue_branches`).

    ``orbits_of_sweep.plan(...)`` (same parameters) checks every input and plans the sweep
    (its memory included) without running anything; the command line plans first, then runs
    the plan with :func:`rockjit.orbits.arclength.run`.

    Parameters
    ----------
    block : Block
        The block.
    forcing : Harmonic
        The excitation with its ``omega`` and no ``alpha``; its phase, or the study's forcing
        point (the section of the branches is the sweep's).
    alpha_range : (float, float)
        The amplitudes, ``start < end``.
    alpha_step : float
        The sweep's step.
    integration : Integration, optional
        The sweep's periods, steps per period, ... (:func:`rockjit.sweep`); its ``theta_over``
        and ``rest_speed`` are the shooting runs' too unless ``shooting`` is given.
    n_steps : int
        Steps per forcing period of the shooting runs (even, ``>= 8``), default
        :data:`N_ORBIT`.
    shooting : Shooting, optional
        As in :func:`continuation`.
    settings : ContinuationSettings, optional
        As in :func:`continuation`; ``max_period`` also bounds the sweep's cells that seed.
    execution : Execution, optional
        How the sweep runs: threads, chunks, Dask, a chunk store, progress (never changes a
        result).

    Returns
    -------
    (Continuation, SweepResult)
        The branches and bifurcations, and the sweep that seeded them.

    Raises
    ------
    ValueError
        For bad input, naming the parameter.

    Examples
    --------
    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import ContinuationSettings, orbits_of_sweep
    >>> cont, sw = orbits_of_sweep(Block(hb=1), Harmonic(omega=1.3), (0.79, 0.81),
    ...                            alpha_step=0.01, settings=ContinuationSettings(switch=False))
    >>> sw.alpha.size, len(cont.branches), cont.branches[0].period
    (3, 1, 1)
    >>> orbits_of_sweep.plan(Block(hb=1), Harmonic(omega=1.3), (0.8, 0.7))
    Traceback (most recent call last):
    ...
    ValueError: alpha_range must satisfy start <= end (got 0.8, 0.7)
    """
    block = check_block(block)
    forcing, _ = check_forcing(forcing, "omega", "-alpha", why="orbits_of_sweep")
    a0, a1 = _range("alpha_range", alpha_range, 0.0)
    integration, _, execution = gp.objects(block, integration, None, execution)
    sweep_plan = sweep_grid.sweep.plan(block, forcing, gp.alpha_grid((a0, a1), alpha_step),
                                       integration=integration, execution=execution)
    n_steps = check_n_steps(n_steps, 10**6)
    if shooting is None:
        shooting = Shooting(theta_over=integration.theta_over,
                            rest_speed=integration.rest_speed)
    return OrbitsPlan(sweep_plan=sweep_plan, block=block, forcing=forcing,
                      alpha_range=(a0, a1), n_steps=n_steps, shooting=check_shooting(shooting),
                      settings=_settings(settings))
