"""Codimension-one bifurcation curves in the forcing plane ``(alpha, omega)``: a fold, symmetry
breaking, period doubling or grazing located along ``alpha`` (:mod:`.arclength`) is followed as
both forcing parameters vary, by pseudo-arclength continuation of an extended system.

Definitions and choices
-----------------------
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
from dataclasses import dataclass, replace

import numpy as np

from ..excitation import ALPHA_MAX, OMEGA_RANGE, Harmonic
from ..validate import integer, pair, real
from .bifurcations import BranchPoint, unit
from .grazing import Depth, deficit_gradient, push_onto
from .shooting import N_ORBIT, Flow, Solver, check_block, check_n_steps, check_shooting, failure
from .types import Bifurcation, ContinuationSettings, OrbitRefused, _set

__all__ = ["CODIM2_TYPES", "CURVE_ENDS", "CURVE_TYPES", "BifurcationCurve", "Codim2Point",
           "CurveSettings", "continue_curve", "relocate"]

#: The codimension-one curves followed.
CURVE_TYPES = ("fold", "symmetry_breaking", "period_doubling", "grazing")

#: The codimension-two points a curve reports (module docstring, "Codimension two").
CODIM2_TYPES = ("fold_flip", "resonance_1_1", "resonance_1_2", "cusp", "grazing_fold",
                "grazing_symmetry_breaking", "grazing_period_doubling", "double_grazing",
                "degenerate_pitchfork", "degenerate_flip")

#: Why a curve ends at either end.
CURVE_ENDS = {
    "range": "it leaves the chart (last point on its edge)",
    "grazing": "its orbit's impact count changes: it meets a grazing curve",
    "overturn": "its orbit overturns (reaches theta_over)",
    "rest": "its orbit comes to rest",
    "branch_point": "its orbit becomes symmetric, or of half the period",
    "closed": "the curve closes on itself",
    "unstable": "its orbit's largest multiplier exceeds max_multiplier",
    "no_convergence": "the corrector fails at the smallest step",
    "max_points": "the bound on points",
    "budget": "the bound on runs",
}

_TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------------------------------------
# settings and results
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class CurveSettings:
    """How a curve is followed in the plane.

    Parameters
    ----------
    ds0, ds_min, ds_max : float
        First, smallest and largest pseudo-arclength step in ``(theta, theta', alpha, omega)``,
        ``0 < ds_min <= ds0 <= ds_max``; defaults 0.01, ``1e-7``, 0.04.
    max_points : int
        Points per direction, ``>= 2``; default 1000.
    max_calls : int
        Runs spent per curve, ``>= 1``; default 200,000.
    param_tol : float
        Codimension-two points and curve ends are located to this in the plane, ``> 0``;
        default ``1e-8``.
    max_multiplier : float
        A curve is not followed where its orbit's largest ``|mu|`` exceeds this (end
        ``"unstable"``; a seed beyond it is refused), ``> 1``; default ``1e4``. So unstable an
        orbit is invisible to the brute-force chart, and its shooting degrades: a state error
        along the unstable direction grows by ``|mu|`` over the cycle, beyond the reach of the
        differences of the grazing condition, and the steps shrink without end.

    Examples
    --------
    >>> from rockjit.orbits import CurveSettings
    >>> CurveSettings().ds_max
    0.04
    >>> CurveSettings(ds0=1.0)
    Traceback (most recent call last):
    ...
    ValueError: need ds_min <= ds0 <= ds_max (got 1e-07, 1.0, 0.04)
    """

    ds0: float = 0.01
    ds_min: float = 1e-7
    ds_max: float = 0.04
    max_points: int = 1000
    max_calls: int = 200_000
    param_tol: float = 1e-8
    max_multiplier: float = 1e4

    def __post_init__(self):
        _set(self, max_multiplier=real("max_multiplier", self.max_multiplier, 1.0, None,
                                       lo_open=True))
        for name in ("ds0", "ds_min", "ds_max", "param_tol"):
            _set(self, **{name: real(name, getattr(self, name), 0.0, None, lo_open=True)})
        if not self.ds_min <= self.ds0 <= self.ds_max:
            raise ValueError(f"need ds_min <= ds0 <= ds_max (got {self.ds_min}, {self.ds0}, "
                             f"{self.ds_max})")
        _set(self, max_points=integer("max_points", self.max_points, 2),
             max_calls=integer("max_calls", self.max_calls, 1))

    def replace(self, **changes):
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)


@dataclass
class Codim2Point:
    """A codimension-two point met along a curve (one of :data:`CODIM2_TYPES`).

    Attributes
    ----------
    type : str
    alpha, omega : float
    state : ndarray, shape (2,)
        The orbit's first cycle point there (at the curve's phase).
    multipliers : ndarray of complex, shape (2,)
    index : int
        The curve point it lies after (between points ``index`` and ``index + 1``; at an end,
        the end point).
    located : bool
        Located by Brent's method to ``param_tol`` (False: the nearest curve point).
    detail : str

    Examples
    --------
    >>> import numpy as np
    >>> from rockjit.orbits import Codim2Point
    >>> c = Codim2Point("cusp", 0.65, 3.8, np.zeros(2), np.array([1.0, 0.48]), 12, False)
    >>> c.to_dict()["type"], c.to_dict()["multipliers"]
    ('cusp', [[1.0, 0.0], [0.48, 0.0]])
    """

    type: str
    alpha: float
    omega: float
    state: np.ndarray
    multipliers: np.ndarray
    index: int
    located: bool = True
    detail: str = ""

    def to_dict(self):
        """JSON-ready (multipliers as ``[re, im]`` pairs)."""
        return dict(type=self.type, alpha=float(self.alpha), omega=float(self.omega),
                    state=np.asarray(self.state, float).tolist(),
                    multipliers=[[float(m.real), float(m.imag)] for m in self.multipliers],
                    index=int(self.index), located=bool(self.located), detail=self.detail)


@dataclass
class BifurcationCurve:
    """A codimension-one curve in the forcing plane, ordered along its arclength.

    Attributes
    ----------
    type : str
        One of :data:`CURVE_TYPES`.
    period : int
        Period of the orbit that bifurcates (or grazes).
    law : str
        The block's restitution law.
    symmetric : bool
        Solved on the half map (a symmetric orbit).
    grazing : str or None
        For a grazing curve, ``"impact"`` (an excursion touches ``theta = 0`` at zero speed)
        or ``"overturn"`` (``max|theta|`` touches ``theta_over``).
    alpha, omega : ndarray, shape (n,)
        The curve.
    state : ndarray, shape (n, 2)
        The orbit's first cycle point at each curve point, at the section ``phase``.
    cycle, cycle_half : ndarray, shape (n, p, 2)
        The cycle at ``kT`` and ``kT + T/2`` (the mirror orbit of a non-symmetric one is
        ``-cycle_half``).
    multipliers : ndarray of complex, shape (n, 2)
    impacts : ndarray of int, shape (n,)
        Impacts per cycle.
    condition : ndarray, shape (n,)
        The defining condition's residual at each point (``det(M -+ I)``, or the grazing
        depth in radians).
    residual : ndarray, shape (n,)
        ``max|fixed-point equations|`` at each point.
    critical : ndarray, shape (n,)
        ``min |mu - c|`` over the multipliers, ``c = +1`` (fold, symmetry breaking) or ``-1``
        (period doubling); ``nan`` for grazing.
    ends : tuple of str
        Why the curve ends at its first and last point (:data:`CURVE_ENDS`).
    codim2 : list of Codim2Point
    phase : float
        The forcing phase of the section.
    seed : dict
        The bifurcation it was followed from (:meth:`Bifurcation.to_dict`'s fields that
        place it).
    n_simulate : int
        Runs spent.
    wall_s : float
    n_steps : int

    Examples
    --------
    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import (ContinuationSettings, CurveSettings, continuation,
    ...                             continue_curve)
    >>> c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
    ...                  bounds=(0.77, 0.8), settings=ContinuationSettings(switch=False))
    >>> sb = c.bifurcations[0]
    >>> curve = continue_curve(Block(hb=1), sb, phase=c.phase, alpha_range=(0.7, 0.85),
    ...                        omega_range=(1.25, 1.35))
    >>> curve.type, curve.ends
    ('symmetry_breaking', ('range', 'range'))
    >>> bool(abs(curve.critical).max() < 1e-9)
    True
    """

    type: str
    period: int
    law: str
    symmetric: bool
    grazing: str | None
    alpha: np.ndarray
    omega: np.ndarray
    state: np.ndarray
    cycle: np.ndarray
    cycle_half: np.ndarray
    multipliers: np.ndarray
    impacts: np.ndarray
    condition: np.ndarray
    residual: np.ndarray
    critical: np.ndarray
    ends: tuple
    codim2: list
    phase: float
    seed: dict
    n_simulate: int
    wall_s: float
    n_steps: int
    block: object = None
    shooting: object = None
    count: int = 0  # the impacts the extended system keeps (over the half map's stretch)

    @property
    def points(self) -> np.ndarray:
        """``(n, 2)``: ``(alpha, omega)`` along the curve."""
        return np.stack([self.alpha, self.omega], 1)

    def __len__(self):
        return self.alpha.shape[0]

    def alpha_at(self, omega):
        """The curve's ``alpha`` values where it crosses ``omega`` (linear interpolation
        between its points; several where it turns in ``omega``)."""
        w = self.omega - omega
        out = []
        for k in np.nonzero(w[:-1] * w[1:] <= 0)[0]:
            dw = self.omega[k + 1] - self.omega[k]
            s = 0.5 if dw == 0 else (omega - self.omega[k]) / dw
            a = float(self.alpha[k] + s * (self.alpha[k + 1] - self.alpha[k]))
            if not out or abs(a - out[-1]) > 1e-12:  # a point on omega is in two segments
                out.append(a)
        return out

    def solve_at(self, omega):
        """The curve's ``alpha`` where it crosses ``omega``, solved there (not interpolated):
        the extended system corrected at fixed ``omega`` from each crossing of the curve's
        points, one value per crossing (``nan`` where the corrector fails).

        Examples
        --------
        >>> from rockjit import Block, Harmonic
        >>> from rockjit.orbits import ContinuationSettings, continuation, continue_curve
        >>> c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
        ...                  bounds=(0.77, 0.8), settings=ContinuationSettings(switch=False))
        >>> curve = continue_curve(Block(hb=1), c.bifurcations[0], phase=c.phase,
        ...                        alpha_range=(0.7, 0.85), omega_range=(1.2, 1.4))
        >>> [round(a, 9) for a in curve.solve_at(1.25)]
        [0.806781978]
        """
        omega = real("omega", omega, *OMEGA_RANGE)
        box = (0.0, ALPHA_MAX, OMEGA_RANGE[0], OMEGA_RANGE[1])
        flow, solver, ext, tracer = _system(self.block, self.type, self.period, self.symmetric,
                                            self.grazing, self.count, self.phase, self.n_steps,
                                            self.shooting, box, CurveSettings())
        w = self.omega - omega
        out = []
        for k in np.nonzero(w[:-1] * w[1:] <= 0)[0]:
            dw = self.omega[k + 1] - self.omega[k]
            s = 0.5 if dw == 0 else (omega - self.omega[k]) / dw
            a = float(self.alpha[k] + s * (self.alpha[k + 1] - self.alpha[k]))
            if out and abs(a - out[-1][0]) < 1e-12:
                continue
            x = self.state[k] + s * (self.state[k + 1] - self.state[k])
            lam = (a, omega)
            try:
                j, xj = _section(solver, x, lam, self.period)
            except OrbitRefused:
                out.append((a, math.nan))
                continue
            y0 = np.r_[xj, lam]
            ev0 = ext(y0, j)
            if not ev0.ok and ext.depth is not None:
                ev0 = tracer.enter_side(y0, j, ev0)
                y0 = y0 if ev0 is None or not ev0.ok else ev0.y
            ok, y, _, _, _ = tracer.correct(y0, np.array([0.0, 0.0, 0.0, 1.0]), j,
                                            max_iter=40, max_jac=40)
            out.append((a, float(y[2]) if ok else math.nan))
        return [v for _, v in out]

    def through(self, omega, alpha, cycle, tol=1e-3):
        """Whether the curve crosses ``omega`` within ``tol`` (relative) of ``alpha``, with an
        orbit there within 5 % of its size of ``cycle`` (or of its mirror image): the same
        curve, found again."""
        from ..grids.cycles import cycle_distance
        w = self.omega - omega
        for k in np.nonzero(w[:-1] * w[1:] <= 0)[0]:
            dw = self.omega[k + 1] - self.omega[k]
            s = 0.5 if dw == 0 else (omega - self.omega[k]) / dw
            a = self.alpha[k] + s * (self.alpha[k + 1] - self.alpha[k])
            if abs(a - alpha) > tol * max(1.0, abs(alpha)):
                continue
            scale = max(float(np.abs(cycle).max()), 1e-12)
            for cyc in (self.cycle, -self.cycle_half):
                ci = (1 - s) * cyc[k] + s * cyc[k + 1]
                if cycle_distance(ci, np.asarray(cycle)) <= 0.05 * scale:
                    return True
        return False

    def to_dict(self, points=True):
        """JSON-ready: type, period, law, ``points`` ``[[alpha, omega], ...]``, ends,
        codimension-two points, the largest residuals."""
        d = dict(type=self.type, period=int(self.period), law=self.law,
                 symmetric=bool(self.symmetric), grazing=self.grazing, n_points=len(self),
                 ends=list(self.ends), codim2=[c.to_dict() for c in self.codim2],
                 max_condition=float(np.max(np.abs(self.condition))) if len(self) else 0.0,
                 max_residual=float(np.max(self.residual)) if len(self) else 0.0,
                 max_critical=float(np.nanmax(self.critical)) if len(self) and
                 np.isfinite(self.critical).any() else None,
                 alpha_range=[float(self.alpha.min()), float(self.alpha.max())],
                 omega_range=[float(self.omega.min()), float(self.omega.max())],
                 phase=self.phase, seed=self.seed, n_simulate=self.n_simulate,
                 wall_s=self.wall_s)
        if points:
            d["points"] = self.points.tolist()
        return d

    def arrays(self, prefix):
        """The curve's arrays for an ``.npz``, each name prefixed."""
        mu = np.asarray(self.multipliers, complex)
        return {prefix + "alpha": self.alpha, prefix + "omega": self.omega,
                prefix + "state": self.state, prefix + "cycle": self.cycle,
                prefix + "multipliers": np.stack([mu.real, mu.imag], -1),
                prefix + "impacts": self.impacts, prefix + "condition": self.condition,
                prefix + "residual": self.residual, prefix + "critical": self.critical}


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


def _section(solver, x, lam, p):
    """The computational section for a seed at ``x``: ``(j, x at that section, run)``."""
    ev = solver.full(x, lam, p, 0)
    if not ev.ok:
        raise OrbitRefused(ev.reason, "at the seed")
    cur, best, mbest = solver.margins_of(ev.r.impacts[:, 0], solver.flow.period(lam), 0)
    if cur < 0.3 * mbest:
        return best, ev.r.trajectory[best, 1:3].copy()
    return 0, np.array(x, float)


def _grazing_seed(solver, seed, lam0, shooting):
    """The orbit at a located grazing that the grazing condition is solved on: ``(kind, x,
    info, (alpha, omega), count)``, ``kind`` ``"impact"`` or ``"overturn"``: the seed's
    orbit, or the one next to it, whose excursion just misses ``theta = 0`` without impact,
    or whose largest ``|theta|`` nears ``theta_over``. On the other side of a grazing the
    excursion touches down twice at low speed and comes back: if only that orbit is found,
    it is returned with ``count``, the impacts of the orbit without that pair (otherwise
    ``None``), and the solve starts by leaving it (:meth:`Tracer.enter_side`)."""
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


def _system(block, ctype, p, symmetric, kind, count, phase, n_steps, shooting, box, settings,
            flow=None, solver=None):
    """The flow, solver, extended system and tracer of a curve."""
    flow = PlaneFlow(block, phase, n_steps, shooting) if flow is None else flow
    solver = Solver(flow, shooting) if solver is None else solver
    depth = None if kind is None else Depth(block, flow, kind, p, symmetric)
    ext = Extended(solver, ctype, p, "sym" if symmetric else "full", count, depth)
    return flow, solver, ext, Tracer(ext, box, settings, shooting.sym_tol)


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
    The extended systems, the Jacobian and the ends: the module's docstring
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
    a0, a1 = pair("alpha_range", alpha_range, 0.0, ALPHA_MAX)
    w0, w1 = pair("omega_range", omega_range, *OMEGA_RANGE)
    if a1 <= a0 or w1 <= w0:
        raise ValueError(f"alpha_range and omega_range must have start < end (got "
                         f"({a0:g}, {a1:g}), ({w0:g}, {w1:g}))")
    alpha, omega = float(seed.alpha), float(seed.omega)
    if not (a0 <= alpha <= a1 and w0 <= omega <= w1):
        raise ValueError(f"the seed's {seed.type} at (alpha, omega) = ({alpha:.6g}, "
                         f"{omega:.6g}) lies outside the chart alpha_range = ({a0:g}, {a1:g}), "
                         f"omega_range = ({w0:g}, {w1:g})")
    n_steps = check_n_steps(n_steps)
    shooting = check_shooting(shooting)
    settings = CurveSettings() if settings is None else settings
    if not isinstance(settings, CurveSettings):
        raise ValueError(f"settings must be a rockjit.orbits.CurveSettings (got "
                         f"{type(settings).__name__})")
    flow = PlaneFlow(block, phase, n_steps, shooting)
    solver = Solver(flow, shooting)
    p = seed.period
    lam0 = (alpha, omega)
    kind = None
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
    _, _, ext, tracer = _system(block, seed.type, p, symmetric, kind, count, phase, n_steps,
                                shooting, (a0, a1, w0, w1), settings, flow, solver)
    depth = ext.depth
    if depth is not None:
        ev0 = ext(np.r_[xj, lam0], j)
        if not ev0.ok:
            ev0 = tracer.enter_side(np.r_[xj, lam0], j, ev0)
            if ev0 is None or not ev0.ok:
                raise OrbitRefused("grazing", "no state next to the seed's orbit misses "
                                              "theta = 0 without impact")
            xj = ev0.y[:2]
    # the seed corrected at its omega, then the curve both ways
    ok, y, ev, _, why = tracer.correct(np.r_[xj, lam0], np.array([0.0, 0.0, 0.0, 1.0]), j,
                                       max_iter=40, max_jac=40)
    if not ok:
        raise OrbitRefused(why or "no_convergence",
                           f"the extended system at the seed ({seed.type}, p={p})")
    if abs(y[2] - alpha) > 1e-6 * max(1.0, alpha):
        raise OrbitRefused("grazing", f"the {seed.type} condition holds at alpha = "
                                      f"{y[2]:.10g} at this omega, not at the seed's "
                                      f"{alpha:.10g}: the seed's branch ends otherwise")
    start = tracer.point(y, j, ev)
    start.g, start.res = float(ev.g), float(np.abs(ev.F).max())
    if float(np.abs(start.info.mu).max()) > settings.max_multiplier:
        raise OrbitRefused("unstable", f"the seed's orbit has |mu| = "
                                       f"{float(np.abs(start.info.mu).max()):.3g} > "
                                       f"max_multiplier = {settings.max_multiplier:g}")
    t = tracer.tangent(start)
    if t is None:
        raise OrbitRefused("singular", "no tangent to the curve at the seed")
    plus, end_p = tracer.march(start, t)
    if end_p == "closed":
        minus, end_m = [], "closed"
    else:
        start2 = BranchPoint(start.y.copy(), start.j, start.jt, start.info)
        minus, end_m = tracer.march(start2, -t)
    pts = minus[::-1] + [start] + plus
    A = np.array([P.y[2] for P in pts])
    W = np.array([P.y[3] for P in pts])
    codim2 = tracer.codim2
    for c2 in codim2:  # the curve point each lies at or after
        c2.index = int(np.argmin(np.hypot(A - c2.alpha, W - c2.omega)))
    codim2.sort(key=lambda c: c.index)
    crit = [float(np.min(np.abs(P.info.mu - ext.c))) if depth is None else math.nan
            for P in pts]
    seed_rec = dict(type=seed.type, parameter=seed.parameter, alpha=float(seed.alpha),
                    omega=float(seed.omega), period=int(seed.period),
                    state=np.asarray(seed.state, float).tolist())
    return BifurcationCurve(
        type=seed.type, period=p, law=block.law, symmetric=symmetric, grazing=kind,
        alpha=A, omega=W, state=np.array([P.info.cycle[0] for P in pts]),
        cycle=np.array([P.info.cycle for P in pts]),
        cycle_half=np.array([P.info.half for P in pts]),
        multipliers=np.array([P.info.mu for P in pts]),
        impacts=np.array([P.info.nimp for P in pts], np.int64),
        condition=np.array([P.g for P in pts]), residual=np.array([P.res for P in pts]),
        critical=np.array(crit),
        ends=(end_m, end_p), codim2=codim2, phase=phase, seed=seed_rec,
        n_simulate=flow.calls, wall_s=time.perf_counter() - t0, n_steps=n_steps,
        block=block, shooting=shooting, count=count)


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


