"""Codimension-one bifurcation curves in the forcing plane ``(alpha, omega)``: a fold, symmetry
breaking, period doubling or grazing located along ``alpha`` (:mod:`.arclength`) is followed as
both forcing parameters vary, by pseudo-arclength continuation of an extended system.

This module follows a curve from its seed (:func:`continue_curve`) and checks a point of it
against the one-parameter location (:func:`relocate`). The curve types, ends and settings are in
:mod:`.curve_types`, the extended systems in :mod:`.extended`, the continuation that follows
one in :mod:`.tracer`, and the curve it returns in :mod:`.bifurcation_curve`.

Definitions and choices
-----------------------
Extended system, Jacobian
    The unknowns ``y = (theta, theta', alpha, omega)``, each curve type's fixed-point
    equations and defining condition, and their Jacobian: :mod:`.extended`.
Continuation
    Pseudo-arclength in ``y`` (Keller 1977), secant predictor, step grown by 1.3 after at most
    six iterations and halved after a failure, between ``ds_min`` and ``ds_max``; the
    computational section moved as in :mod:`.arclength`. A curve ends where it leaves the
    chart (the last point solved on its edge), where its orbit's impact count changes (it
    meets a grazing curve), where the orbit overturns or comes to rest, where an asymmetric
    orbit becomes symmetric or a period-``2p`` orbit period ``p`` (a branch point), on closing,
    where its orbit's largest multiplier exceeds ``max_multiplier``, or at a bound on points
    or runs (:data:`CURVE_ENDS`).
Grazing
    The turning point of ``|theta|`` nearest ``theta = 0`` (or of ``theta_over``) is found on
    the run's grid and refined by quintic Hermite interpolation from ``theta``, ``theta'`` and
    ``theta''`` (the equations of motion) at the two grid points around it (error
    ``O(h^6)``): its depth is the condition, smooth on the side where that excursion has no
    impact (:mod:`.grazing`). That side is the one solved on: each Newton step aims at a depth
    of 0.3 times the tolerance, and a predictor or iterate whose excursion crossed (it touches
    down twice at low speed and comes back, or overturns) is pushed back onto the side along
    the direction that raises the condition, by the secant method on the estimated overshoot.
    The seed is the orbit at the located grazing of :mod:`.bifurcations`, or the one without
    the low-speed double impact next to it. For a symmetric orbit the condition is read off
    the half map's stretch (the minimum of the two mirror depths would not be smooth).
Codimension two
    Between consecutive points, sign changes of ``det(M - I)``, ``det(M + I)`` and ``det M - 1``
    are located by Brent's method along the chord, each trial a corrected point
    (``fold_flip``, ``resonance_1_1``, ``resonance_1_2`` on the multiplier curves;
    ``grazing_fold``, ``grazing_symmetry_breaking``, ``grazing_period_doubling`` on a grazing
    curve). A fold curve whose projection on the plane turns back marks a ``cusp`` (located
    to the step); a curve that ends on a grazing curve, the grazing point of its type
    (``grazing_<type>``; a grazing curve ending where another excursion of its orbit grazes,
    a ``double_grazing``); an asymmetric fold curve
    that ends on its orbit's symmetric parent, a ``degenerate_pitchfork``, and a
    period-``2p`` fold curve on its period-``p`` parent, a ``degenerate_flip``. In this
    dissipative model ``|det M| < 1`` (:mod:`.bifurcations`, "Neimark–Sacker"), so a fold
    meeting a flip and the 1:1 and 1:2 resonances need ``e = 1`` and ``xi = 0``: they are
    watched for, and cannot occur otherwise.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..excitation import ALPHA_MAX, OMEGA_RANGE, Harmonic
from ..validate import integer, pair, real
from .bifurcation_curve import BifurcationCurve
from .bifurcations import BranchPoint
from .curve_types import CURVE_TYPES, CurveSettings
from .extended import PlaneFlow
from .grazing import Depth
from .shooting import N_ORBIT, Solver, check_block, check_n_steps, check_shooting, failure
from .tracer import _section, _system
from .types import Bifurcation, ContinuationSettings, OrbitRefused

__all__ = ["continue_curve", "relocate"]


# ---------------------------------------------------------------------------------------------
# seeds
# ---------------------------------------------------------------------------------------------

def _check_seed(seed):
    if not isinstance(seed, Bifurcation):
        raise ValueError(f"seed must be a rockjit.orbits.Bifurcation (got "
                         f"{type(seed).__name__})")
    if seed.type not in CURVE_TYPES:
        raise ValueError(f"a {seed.type} is not continued in the plane (curves: "
                         f"{', '.join(CURVE_TYPES)})")
    return seed


def _grazing_seed(solver, seed, lam0, shooting):
    """The orbit at a located grazing that the grazing condition is solved on: ``(kind, x,
    info, (alpha, omega), count)``, ``kind`` ``"impact"`` or ``"overturn"``: the seed's
    orbit, or the one next to it, whose excursion just misses ``theta = 0`` without impact,
    or whose largest ``|theta|`` nears ``theta_over``. On the other side of a grazing the
    excursion touches down twice at low speed and comes back: if only that orbit is found,
    it is returned with ``count``, the impacts of the orbit without that pair (otherwise
    ``None``), and the solve starts by leaving it
    (:meth:`rockjit.orbits.tracer.Tracer.enter_side`)."""
    p = seed.period
    alpha, omega = lam0
    scale = max(float(np.abs(seed.cycle).max()), 1e-12)
    flow = solver.flow
    near = Depth(seed_block(flow), flow, "impact", p, False)
    found = fallback = None
    for da in (0.0, 1e-7, -1e-7, 1e-6, -1e-6, 1e-5, -1e-5, 1e-4, -1e-4, 1e-3, -1e-3):
        lam = (alpha + da, omega)
        if not flow.valid(lam):
            continue
        try:
            ev, _ = solver.newton(np.array(seed.state, float), lam, p, 0, scale, max_iter=30)
        except OrbitRefused:
            continue
        info = solver.analyse(ev.r, lam, p, 0)
        if info.max_theta >= shooting.theta_over * (1.0 - 1e-2):
            found = ("overturn", ev.x, info, lam, None)
            break
        depth = near(ev.r, lam, 0)
        if depth is not None and depth < 1e-3 * info.max_theta:
            found = ("impact", ev.x, info, lam, None)
            break
        speed = np.abs(ev.r.impacts[:, 1]) / max(float(np.abs(ev.r.trajectory[:, 2]).max()),
                                                 1e-300)
        if fallback is None and np.count_nonzero(speed < 0.05) >= 2:
            # an excursion that touches down and comes back at low speed: the orbit without
            # those two impacts, next to it, is the one solved on
            fallback = ("impact", ev.x, info, lam, int(ev.r.n_impacts) - 2)
    found = found or fallback
    if found is None:
        raise ValueError(f"no orbit near the grazing at alpha = {alpha:.10g}, omega = "
                         f"{omega:.10g} has an excursion that just misses theta = 0 or "
                         f"theta_over (it ends at rest, or in a rest phase): not continued")
    return found


def seed_block(flow):
    """The block of a flow."""
    return flow.block


def continue_curve(block, seed, *, phase, alpha_range, omega_range, n_steps=N_ORBIT,
                   shooting=None, settings=None) -> BifurcationCurve:
    """Follow a located bifurcation in the forcing plane ``(alpha, omega)``.

    Parameters
    ----------
    block : Block
        The block the bifurcation was located for.
    seed : Bifurcation
        A fold, symmetry breaking, period doubling or grazing located by
        :func:`rockjit.orbits.continuation` (or :func:`~rockjit.orbits.continue_branches`),
        with the orbit's state at that continuation's phase.
    phase : float
        That continuation's forcing phase (``Continuation.phase``): the stroboscopic section.
    alpha_range, omega_range : (float, float)
        The chart: the curve ends where it leaves it. It must contain the seed.
    n_steps : int
        Steps per forcing period (even, ``>= 8``), default :data:`rockjit.orbits.N_ORBIT`
        (the seed's continuation's, for the 1e-8 agreement).
    shooting : Shooting, optional
        Newton's tolerance, the symmetry tolerance, the runs' impact bound, ``theta_over``
        and Zeno cut-off (those of the seed's continuation).
    settings : CurveSettings, optional

    Returns
    -------
    BifurcationCurve
        Ordered from one end to the other, through the seed.

    Raises
    ------
    ValueError
        For bad input, a seed outside the chart, a Neimark–Sacker seed, or a grazing whose
        orbit has no excursion that just misses ``theta = 0`` or ``theta_over``.
    OrbitRefused
        If the seed's orbit cannot be solved.

    Notes
    -----
    The extended systems and the Jacobian: :mod:`rockjit.orbits.extended`; the continuation,
    its ends and the codimension-two points: the module's docstring
    (:mod:`rockjit.orbits.curves`).

    Examples
    --------
    The first period doubling of the study's case (``h/b = 1``, Housner, ``omega = 1.3``)
    followed in the plane:

    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import ContinuationSettings, continuation, continue_curve
    >>> c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
    ...                  bounds=(0.79, 0.92), settings=ContinuationSettings(switch=False))
    >>> pd = next(b for b in c.bifurcations if b.type == "period_doubling")
    >>> curve = continue_curve(Block(hb=1), pd, phase=c.phase, alpha_range=(0.8, 1.0),
    ...                        omega_range=(1.2, 1.4))
    >>> curve.type, curve.period, curve.ends
    ('period_doubling', 1, ('range', 'range'))
    >>> [round(a, 6) for a in curve.alpha_at(1.3)]
    [0.911511]
    """
    t0 = time.perf_counter()
    block = check_block(block)
    seed = _check_seed(seed)
    phase = real("phase", phase)
    box = _chart_box(seed, alpha_range, omega_range)
    n_steps = check_n_steps(n_steps)
    shooting = check_shooting(shooting)
    settings = _curve_settings(settings)
    flow = PlaneFlow(block, phase, n_steps, shooting)
    solver = Solver(flow, shooting)
    orbit = _seed_orbit(solver, block, seed, shooting)
    _, _, ext, tracer = _system(block, seed.type, seed.period, orbit.symmetric, orbit.kind,
                                orbit.count, phase, n_steps, shooting, box, settings, flow,
                                solver)
    start = _start(tracer, ext, seed, orbit, settings.max_multiplier)
    pts, ends = _both_ways(tracer, start)
    return _curve(seed, orbit, pts, ends, tracer.codim2, ext, block=block, phase=phase,
                  n_simulate=flow.calls, wall_s=time.perf_counter() - t0, n_steps=n_steps,
                  shooting=shooting)


def chart_ranges(alpha_range, omega_range):
    """A chart's ``(a0, a1, w0, w1)`` in the forcing plane, checked (``start < end``)."""
    a0, a1 = pair("alpha_range", alpha_range, 0.0, ALPHA_MAX)
    w0, w1 = pair("omega_range", omega_range, *OMEGA_RANGE)
    if a1 <= a0 or w1 <= w0:
        raise ValueError(f"alpha_range and omega_range must have start < end (got "
                         f"({a0:g}, {a1:g}), ({w0:g}, {w1:g}))")
    return a0, a1, w0, w1


def _chart_box(seed, alpha_range, omega_range):
    """The chart ``(a0, a1, w0, w1)``, checked, with the seed inside it."""
    a0, a1, w0, w1 = chart_ranges(alpha_range, omega_range)
    alpha, omega = float(seed.alpha), float(seed.omega)
    if not (a0 <= alpha <= a1 and w0 <= omega <= w1):
        raise ValueError(f"the seed's {seed.type} at (alpha, omega) = ({alpha:.6g}, "
                         f"{omega:.6g}) lies outside the chart alpha_range = ({a0:g}, {a1:g}), "
                         f"omega_range = ({w0:g}, {w1:g})")
    return a0, a1, w0, w1


def _curve_settings(settings):
    """The curve's settings, checked (default :class:`CurveSettings`)."""
    settings = CurveSettings() if settings is None else settings
    if not isinstance(settings, CurveSettings):
        raise ValueError(f"settings must be a rockjit.orbits.CurveSettings (got "
                         f"{type(settings).__name__})")
    return settings


@dataclass
class _SeedOrbit:
    """The seed's orbit as its curve starts from it."""

    kind: str | None  #: a grazing's ``"impact"`` or ``"overturn"``; else ``None``
    x: np.ndarray  #: ``(theta, theta')`` at the computational section ``j``
    j: int
    lam: tuple  #: ``(alpha, omega)``
    symmetric: bool  #: solved on the half map
    count: int  #: impacts per cycle (over the half map's stretch when symmetric)


def _seed_orbit(solver, block, seed, shooting):
    """The seed's orbit at its computational section, with the impact count its curve keeps."""
    flow, p = solver.flow, seed.period
    lam0 = (float(seed.alpha), float(seed.omega))
    if seed.type == "grazing":
        kind, x, info, lam0, count = _grazing_seed(solver, seed, lam0, shooting)
        symmetric = bool(info.symmetric) and p % 2 == 1
        if symmetric and count is not None:
            count //= 2  # counted over the half map's stretch
    else:
        x = np.array(seed.state, float)
        symmetric = seed.type == "symmetry_breaking" or (seed.type == "fold" and
                                                          not seed.has_mirror)
        kind = count = None
    j, xj = _section(solver, x, lam0, p)
    r = flow.run(xj, lam0, p, j, True)
    if failure(r):
        raise OrbitRefused(failure(r), "at the seed")
    if count is None:
        count = int(r.n_impacts) if kind is None else \
            Depth(block, flow, kind, p, symmetric).count(r, lam0)
    return _SeedOrbit(kind, xj, j, lam0, symmetric, count)


def _start(tracer, ext, seed, orbit, max_multiplier):
    """The curve's first point: the seed's orbit corrected on the extended system at its
    ``omega`` (a grazing's first moved onto the side without the impact)."""
    xj, j, lam0, p = orbit.x, orbit.j, orbit.lam, seed.period
    if ext.depth is not None:
        ev0 = ext(np.r_[xj, lam0], j)
        if not ev0.ok:
            ev0 = tracer.enter_side(np.r_[xj, lam0], j, ev0)
            if ev0 is None or not ev0.ok:
                raise OrbitRefused("grazing", "no state next to the seed's orbit misses "
                                              "theta = 0 without impact")
            xj = ev0.y[:2]
    ok, y, ev, _, why = tracer.correct(np.r_[xj, lam0], np.array([0.0, 0.0, 0.0, 1.0]), j,
                                       max_iter=40, max_jac=40)
    if not ok:
        raise OrbitRefused(why or "no_convergence",
                           f"the extended system at the seed ({seed.type}, p={p})")
    alpha = float(seed.alpha)
    if abs(y[2] - alpha) > 1e-6 * max(1.0, alpha):
        raise OrbitRefused("grazing", f"the {seed.type} condition holds at alpha = "
                                      f"{y[2]:.10g} at this omega, not at the seed's "
                                      f"{alpha:.10g}: the seed's branch ends otherwise")
    start = tracer.point(y, j, ev)
    start.g, start.res = float(ev.g), float(np.abs(ev.F).max())
    if float(np.abs(start.info.mu).max()) > max_multiplier:
        raise OrbitRefused("unstable", f"the seed's orbit has |mu| = "
                                       f"{float(np.abs(start.info.mu).max()):.3g} > "
                                       f"max_multiplier = {max_multiplier:g}")
    return start


def _both_ways(tracer, start):
    """The curve followed both ways from ``start``: its points in order, and its two ends."""
    t = tracer.tangent(start)
    if t is None:
        raise OrbitRefused("singular", "no tangent to the curve at the seed")
    plus, end_p = tracer.march(start, t)
    if end_p == "closed":
        minus, end_m = [], "closed"
    else:
        start2 = BranchPoint(start.y.copy(), start.j, start.jt, start.info)
        minus, end_m = tracer.march(start2, -t)
    return minus[::-1] + [start] + plus, (end_m, end_p)


def _curve(seed, orbit, pts, ends, codim2, ext, *, block, **rest):
    """The :class:`BifurcationCurve` through the points ``pts``, its codimension-two points
    placed along it; ``rest``: the run's phase, counts, timing and settings."""
    A = np.array([P.y[2] for P in pts])
    W = np.array([P.y[3] for P in pts])
    for c2 in codim2:  # the curve point each lies at or after
        c2.index = int(np.argmin(np.hypot(A - c2.alpha, W - c2.omega)))
    codim2.sort(key=lambda c: c.index)
    crit = [float(np.min(np.abs(P.info.mu - ext.c))) if ext.depth is None else math.nan
            for P in pts]
    seed_rec = dict(type=seed.type, parameter=seed.parameter, alpha=float(seed.alpha),
                    omega=float(seed.omega), period=int(seed.period),
                    state=np.asarray(seed.state, float).tolist())
    return BifurcationCurve(
        type=seed.type, period=seed.period, law=block.law, symmetric=orbit.symmetric,
        grazing=orbit.kind, alpha=A, omega=W, state=np.array([P.info.cycle[0] for P in pts]),
        cycle=np.array([P.info.cycle for P in pts]),
        cycle_half=np.array([P.info.half for P in pts]),
        multipliers=np.array([P.info.mu for P in pts]),
        impacts=np.array([P.info.nimp for P in pts], np.int64),
        condition=np.array([P.g for P in pts]), residual=np.array([P.res for P in pts]),
        critical=np.array(crit), ends=ends, codim2=codim2, seed=seed_rec, block=block,
        count=orbit.count, **rest)


# ---------------------------------------------------------------------------------------------
# the one-parameter check: a curve point located again along alpha at its omega
# ---------------------------------------------------------------------------------------------

def relocate(curve, index, *, half_width=2e-3):
    """The ``alpha`` of curve point ``index`` located again by the one-parameter continuation
    along ``alpha`` at its ``omega`` (:func:`rockjit.orbits.continuation`: Brent's method on
    the multiplier's test function, bisection for a grazing), or ``nan``.

    Parameters
    ----------
    curve : BifurcationCurve
    index : int
        The curve point.
    half_width : float
        The continuation's range is the point's ``alpha`` plus or minus this.

    Returns
    -------
    float

    Examples
    --------
    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import (ContinuationSettings, continuation, continue_curve,
    ...                             relocate)
    >>> c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
    ...                  bounds=(0.77, 0.8), settings=ContinuationSettings(switch=False))
    >>> curve = continue_curve(Block(hb=1), c.bifurcations[0], phase=c.phase,
    ...                        alpha_range=(0.7, 0.85), omega_range=(1.28, 1.32))
    >>> k = len(curve) - 1
    >>> bool(abs(relocate(curve, k) - curve.alpha[k]) < 1e-8)
    True
    """
    from .arclength import continuation
    k = integer("index", index, -len(curve), len(curve) - 1) % len(curve)
    a, w = float(curve.alpha[k]), float(curve.omega[k])
    x = curve.state[k]
    settings = ContinuationSettings(switch=False, ds0=min(0.01, half_width / 4),
                                    max_points=400)
    best = math.nan
    forcing = Harmonic(omega=w, phase=curve.phase)
    lo = max(0.0, a - half_width)
    for da in (-0.25, 0.25, -0.5, 0.5):
        sd = a + da * half_width
        try:
            c = continuation(curve.block, forcing, [(sd, x, curve.period)],
                             bounds=(lo, a + half_width), n_steps=curve.n_steps,
                             shooting=curve.shooting.replace(graze_tol=0.0),
                             settings=settings)
        except (OrbitRefused, ValueError):
            continue
        got = [b.alpha for b in c.bifurcations if b.type == curve.type and
               b.period == curve.period and b.located]
        if got:
            cand = min(got, key=lambda v: abs(v - a))
            if math.isnan(best) or abs(cand - a) < abs(best - a):
                best = cand
            if abs(best - a) < 1e-6:
                break
    return best
